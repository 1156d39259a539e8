"""RPLIDAR A1M8 emulation: golden bytes, scan encodings, request parsing, device states.

Expected bytes are written out from the protocol's documented layout (and
its one published example), never produced by the code under test.
"""

from __future__ import annotations

import struct
from functools import reduce
from operator import xor

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from harness.devices import rplidar as rp
from harness.devices import rplidar_scans as scans
from harness.devices.revolution import Sample

SERIAL = bytes(range(0x30, 0x40))
INFO = rp.encode_request(rp.CMD_GET_INFO)
HEALTH = rp.encode_request(rp.CMD_GET_HEALTH)
SCAN = rp.encode_request(rp.CMD_SCAN)
STOP = rp.encode_request(rp.CMD_STOP)
EXPRESS_LEGACY = bytes.fromhex("a5 82 05 00 00 00 00 00 22")  # the protocol document's example


def hx(text: str) -> bytes:
    return bytes.fromhex(text)


def device(**kwargs) -> rp.RplidarDevice:
    return rp.RplidarDevice(serial_number=SERIAL, **kwargs)


def scanning(cmd: bytes = SCAN) -> rp.RplidarDevice:
    dev = device()
    dev.set_motor(True)
    assert dev.receive(cmd)
    return dev


def uniform(n: int, *, offset: float = 0.0, dist=lambda k: 500.0 + 7 * k) -> list[Sample]:
    return [Sample((offset + k * 360.0 / n) % 360.0, float(dist(k)), 47) for k in range(n)]


def angle_error(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


# -- requests as hosts send them ----------------------------------------------------


def test_requests_without_payload_are_two_bytes() -> None:
    assert INFO == hx("a5 50")
    assert HEALTH == hx("a5 52")
    assert rp.encode_request(rp.CMD_GET_SAMPLERATE) == hx("a5 59")
    assert SCAN == hx("a5 20") and STOP == hx("a5 25")
    assert rp.encode_request(rp.CMD_RESET) == hx("a5 40")


def test_payload_requests_carry_size_and_xor_checksum() -> None:
    # The protocol document's EXPRESS_SCAN example: A5 82 05 00 00 00 00 00 22.
    assert rp.encode_request(rp.CMD_EXPRESS_SCAN, bytes(5)) == EXPRESS_LEGACY
    # MOTOR_PWM 660 (what the rplidar package sends): a5^f0^02^94^02 = c1.
    assert rp.encode_request(rp.CMD_SET_MOTOR_PWM, struct.pack("<H", 660)) == hx(
        "a5 f0 02 94 02 c1"
    )
    # GET_LIDAR_CONF as the SDK sends it: u32 type + 32 reserved bytes; a5^84^24^70 = 75.
    conf = rp.encode_request(rp.CMD_GET_LIDAR_CONF, hx("70 00 00 00") + bytes(32))
    assert conf == hx("a5 84 24 70 00 00 00") + bytes(32) + hx("75")
    # A payload sets the 0x80 flag, as the SDK's _sendCommand does.
    assert rp.encode_request(0x04, hx("01")) == hx("a5 84 01 01 21")  # a5^84^01^01


def test_encode_request_refuses_what_cannot_be_sent() -> None:
    with pytest.raises(ValueError):
        rp.encode_request(0x100)
    with pytest.raises(ValueError):
        rp.encode_request(rp.CMD_GET_LIDAR_CONF, bytes(256))


# -- single responses --------------------------------------------------------------


def test_get_info_reply() -> None:
    reply = device().receive(INFO)
    # descriptor: length 20, single, type 04; model 0x18, fw minor 29 (0x1d), major 1, hw 7.
    assert reply == hx("a5 5a 14 00 00 00 04 18 1d 01 07") + SERIAL


def test_get_health_reply_little_endian_error_code() -> None:
    dev = device()
    assert dev.receive(HEALTH) == hx("a5 5a 03 00 00 00 06 00 00 00")
    dev.set_health(rp.HEALTH_WARNING, 0x1234)
    assert dev.receive(HEALTH) == hx("a5 5a 03 00 00 00 06 01 34 12")


def test_get_samplerate_reply() -> None:
    # 508 us = 0x01fc, 254 us = 0x00fe: the A1M8 firmware 1.29 values.
    assert device().receive(hx("a5 59")) == hx("a5 5a 04 00 00 00 15 fc 01 fe 00")


def conf_request(conf_type: int, mode: int | None = None) -> bytes:
    reserved = bytearray(32)
    if mode is not None:
        reserved[0:2] = struct.pack("<H", mode)
    return rp.encode_request(rp.CMD_GET_LIDAR_CONF, struct.pack("<I", conf_type) + reserved)


@pytest.mark.parametrize(
    ("conf_type", "mode", "expected"),
    [
        (0x70, None, "a5 5a 06 00 00 00 20 70 00 00 00 02 00"),  # two scan modes
        (0x7C, None, "a5 5a 06 00 00 00 20 7c 00 00 00 01 00"),  # typical: Express
        (0x71, 0, "a5 5a 08 00 00 00 20 71 00 00 00 00 fc 01 00"),  # 508 us in q8
        (0x71, 1, "a5 5a 08 00 00 00 20 71 00 00 00 00 fe 00 00"),  # 254 us in q8
        (0x74, 1, "a5 5a 08 00 00 00 20 74 00 00 00 00 0c 00 00"),  # 12 m in q8
        (0x75, 0, "a5 5a 05 00 00 00 20 75 00 00 00 81"),
        (0x75, 1, "a5 5a 05 00 00 00 20 75 00 00 00 82"),
        (0x7F, 0, "a5 5a 0d 00 00 00 20 7f 00 00 00" + b"Standard\0".hex()),
        (0x7F, 1, "a5 5a 0c 00 00 00 20 7f 00 00 00" + b"Express\0".hex()),
    ],
)
def test_get_lidar_conf_replies(conf_type: int, mode: int | None, expected: str) -> None:
    assert device().receive(conf_request(conf_type, mode)) == hx(expected)


def test_get_lidar_conf_without_an_answer_stays_silent() -> None:
    dev = device()
    assert dev.receive(conf_request(0x01)) == b""  # DESIRED_ROT_FREQ: not an A1 entry here
    assert dev.receive(conf_request(0x71, 7)) == b""  # no such mode
    assert dev.receive(rp.encode_request(rp.CMD_GET_LIDAR_CONF, hx("70 00"))) == b""
    assert dev.counters["unknown_conf"] == 2 and dev.counters["bad_payload"] == 1


def test_acc_board_flag_says_no_pwm_motor_control() -> None:
    reply = device().receive(rp.encode_request(rp.CMD_GET_ACC_BOARD_FLAG, bytes(4)))
    assert reply == hx("a5 5a 04 00 00 00 ff 00 00 00 00")


# -- standard scan -------------------------------------------------------------------


def test_scan_and_force_scan_descriptors() -> None:
    for request in (SCAN, hx("a5 21")):
        dev = device()
        assert dev.receive(request) == hx("a5 5a 05 00 00 40 81")
        assert dev.mode == "scan"
        assert rp.decode_descriptor(hx("a5 5a 05 00 00 40 81")) == (5, rp.SEND_MULTIPLE, 0x81)


def test_standard_node_golden_bytes() -> None:
    # quality 47, start: 47<<2 | 0b01 = 0xbd; 270 deg = 17280 q6 -> (17280<<1)|1 = 0x8701;
    # 1000 mm = 4000 q2 = 0x0fa0.
    assert scans.encode_node(Sample(270.0, 1000.0, 47), start=True) == hx("bd 01 87 a0 0f")
    # Not a start: !S set; quality 1; 0.5 deg = 32 q6 -> 0x0041; 0.25 mm = 1 q2.
    assert scans.encode_node(Sample(0.5, 0.25, 1), start=False) == hx("06 41 00 01 00")
    # No return: quality forced to 0 whatever the sample says.
    assert scans.encode_node(Sample(90.0, 0.0, 40), start=False) == hx(
        "02 01 2d 00 00"
    )  # 5760 q6 -> 0x2d01


def test_one_revolution_has_one_start_flag_on_the_smallest_angle() -> None:
    samples = uniform(360, offset=0.3)
    rotated = samples[100:] + samples[:100]  # a list that does not begin at the start
    for given_samples in (samples, rotated):
        nodes = scans.decode_standard_nodes(scanning().encode_revolution(given_samples))
        flags = [start for _, start in nodes]
        assert flags.count(True) == 1 and flags[0]
        assert nodes[0][0].angle_deg == min(s.angle_deg for s, _ in nodes)


def test_an_angle_just_below_360_does_not_wrap_to_zero() -> None:
    nodes = scans.decode_standard_nodes(
        scanning().encode_revolution(uniform(4) + [Sample(359.999, 1.0, 5)])
    )
    assert [s.angle_deg for s, _ in nodes] == [0.0, 90.0, 180.0, 270.0, 359.984375]
    assert [start for _, start in nodes] == [True, False, False, False, False]


@settings(max_examples=100, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0, 360, exclude_max=True),
            st.floats(0, 16000),
            st.integers(0, 63),
        ),
        min_size=1,
        max_size=50,
    )
)
def test_standard_round_trip_within_quantisation(values) -> None:
    samples = sorted((Sample(a, d, q) for a, d, q in values), key=lambda s: s.angle_deg)
    decoded = scans.decode_standard(scans.encode_standard(samples))
    first = min(range(len(samples)), key=lambda i: round(samples[i].angle_deg * 64))
    for want, got in zip(samples[first:] + samples[:first], decoded, strict=True):
        # Half a q6 step; just below 360 the last step is kept rather than wrapped to 0.
        bound = 1 / 128 if want.angle_deg < 360 - 1 / 128 else 1 / 64
        assert angle_error(want.angle_deg, got.angle_deg) <= bound + 1e-9
        assert abs(want.distance_mm - got.distance_mm) <= 0.125 + 1e-9
        assert got.quality == (want.quality if got.distance_mm else 0)


def test_decode_standard_rejects_broken_nodes() -> None:
    with pytest.raises(ValueError):
        scans.decode_standard(hx("bf 01 87 a0 0f"))  # S and !S both set
    with pytest.raises(ValueError):
        scans.decode_standard(hx("bd 00 87 a0 0f"))  # check bit clear
    with pytest.raises(ValueError):
        scans.decode_standard(hx("bd 01 87 a0"))  # not a whole node


# -- express scan ----------------------------------------------------------------------


def test_express_scan_descriptor() -> None:
    dev = device()
    assert dev.receive(EXPRESS_LEGACY) == hx("a5 5a 54 00 00 40 82")
    assert dev.mode == "express"
    # Working mode 1 (the SDK sends the scan-mode id) is Express here too.
    assert device().receive(rp.encode_request(0x82, hx("01 00 00 00 00"))) == hx(
        "a5 5a 54 00 00 40 82"
    )


def hand_capsule(start_q6: int, start_flag: bool, cabins: list[tuple[int, int, int, int]]) -> bytes:
    """A capsule from the documented layout: (dist1 mm, dtheta1 q3, dist2 mm, dtheta2 q3)."""
    body = bytearray()
    body += (start_q6 | (0x8000 if start_flag else 0)).to_bytes(2, "little")
    for d1, t1, d2, t2 in cabins:
        body += ((d1 << 2) | (t1 >> 4)).to_bytes(2, "little")
        body += ((d2 << 2) | (t2 >> 4)).to_bytes(2, "little")
        body.append((t1 & 0x0F) | ((t2 & 0x0F) << 4))
    checksum = reduce(xor, body, 0)
    return bytes([0xA0 | (checksum & 0x0F), 0x50 | (checksum >> 4)]) + bytes(body)


def test_express_capsule_golden_bytes() -> None:
    # 32 samples one quarter-degree apart from 10 deg, the next capsule at 18 deg:
    # every sample sits on the interpolated angle, so every dtheta is 0.
    samples = [Sample(10.0 + k * 0.25, 100.0 * k, 47) for k in range(32)]
    cabins = [(100 * 2 * c, 0, 100 * (2 * c + 1), 0) for c in range(16)]
    expected = hand_capsule(10 * 64, True, cabins)
    assert scans.encode_capsule(samples, 18.0, start_flag=True) == expected
    assert len(expected) == 84 and expected[0] >> 4 == 0xA and expected[1] >> 4 == 0x5


def test_express_capsule_angle_compensation_bits() -> None:
    # Sample 1 sits 1.5 deg before its interpolated angle: dtheta = 12 (q3),
    # whose bits 5:4 (0) go in the distance word and bits 3:0 (0xc) in the high nibble.
    samples = [Sample(10.0 + k * 0.25, 1000.0, 47) for k in range(32)]
    samples[1] = Sample(10.25 - 1.5, 1000.0, 47)
    samples[2] = Sample(10.5 - 2.5, 1000.0, 47)  # dtheta 20 = 0b01_0100
    cabins = [(1000, 0, 1000, 0) for _ in range(16)]
    cabins[0] = (1000, 0, 1000, 12)
    cabins[1] = (1000, 20, 1000, 0)
    assert scans.encode_capsule(samples, 18.0) == hand_capsule(640, False, cabins)
    decoded = scans.decode_express(
        hand_capsule(640, False, cabins), hand_capsule(18 * 64, False, cabins)
    )
    assert decoded[1].angle_deg == pytest.approx(8.75) and decoded[2].angle_deg == pytest.approx(
        8.0
    )


def test_express_round_trip_within_capsule_resolution() -> None:
    dev = scanning(EXPRESS_LEGACY)
    per_rev = dev.samples_per_revolution(5.5)  # 254 us per sample: 716
    revolutions = [uniform(per_rev, offset=0.2, dist=lambda k: 150.0 + 13.3 * k) for _ in range(3)]
    stream = b"".join(dev.encode_revolution(r) for r in revolutions)
    assert len(stream) % 84 == 0
    capsules = [stream[i : i + 84] for i in range(0, len(stream), 84)]
    decoded = [
        s for a, b in zip(capsules, capsules[1:], strict=False) for s in scans.decode_express(a, b)
    ]
    sent = [s for r in revolutions for s in r][: len(decoded)]
    assert len(decoded) >= 2 * per_rev
    for want, got in zip(sent, decoded, strict=True):
        # dtheta is 1/8 deg (half a step of rounding) plus the SDK's floor to q6.
        assert angle_error(want.angle_deg, got.angle_deg) <= 1 / 16 + 1 / 64 + 1e-9
        assert abs(want.distance_mm - got.distance_mm) <= 0.5  # whole millimetres
    assert [scans.capsule_start_flag(c) for c in capsules].count(True) == 1
    assert scans.capsule_start_flag(capsules[0])


def test_express_restarts_after_the_motor_stalls() -> None:
    dev = scanning(EXPRESS_LEGACY)
    first = dev.encode_revolution(uniform(700))
    dev.set_motor(False)
    assert dev.encode_revolution(uniform(700)) == b""
    dev.set_motor(True)
    again = dev.encode_revolution(uniform(700))
    assert scans.capsule_start_flag(first[:84]) and scans.capsule_start_flag(again[:84])
    assert not scans.capsule_start_flag(again[84:168])


def test_decode_express_checks_capsules() -> None:
    good = hand_capsule(0, False, [(0, 0, 0, 0)] * 16)
    with pytest.raises(ValueError):
        scans.decode_express(good[:-1], good)
    with pytest.raises(ValueError):
        scans.decode_express(bytes([good[0] ^ 1]) + good[1:], good)  # checksum
    with pytest.raises(ValueError):
        scans.decode_express(bytes([0x50 | (good[0] & 0xF)]) + good[1:], good)  # sync nibble


def test_express_modes_the_emulator_does_not_stream_are_ignored() -> None:
    dev = device()
    assert dev.receive(rp.encode_request(0x82, hx("03 00 00 00 00"))) == b""  # Sensitivity
    assert dev.receive(rp.encode_request(0x82, hx("00 00 00"))) == b""  # payload too short
    assert dev.mode == "idle"
    assert dev.counters["unsupported_mode"] == 1 and dev.counters["bad_payload"] == 1


# -- request parsing -------------------------------------------------------------------


def test_requests_split_across_calls() -> None:
    whole = device().receive(conf_request(0x7F, 1))
    dev = device()
    parts = [dev.receive(bytes([b])) for b in conf_request(0x7F, 1)]
    assert b"".join(parts) == whole and all(p == b"" for p in parts[:-1])


def test_garbage_before_the_sync_byte_is_skipped_and_counted() -> None:
    dev = device()
    assert dev.receive(hx("00 13 ff 5a") + INFO) == hx("a5 5a 14 00 00 00 04 18 1d 01 07") + SERIAL
    assert dev.counters["garbage_bytes"] == 4
    assert dev.receive(hx("a5") + HEALTH)[:2] == hx("a5 5a")  # a doubled sync byte
    assert dev.counters["garbage_bytes"] == 5


def test_bad_checksum_is_dropped_silently() -> None:
    dev = device()
    bad = bytearray(EXPRESS_LEGACY)
    bad[-1] ^= 0x01
    assert dev.receive(bytes(bad)) == b""
    assert dev.mode == "idle" and dev.counters["bad_checksum"] == 1
    assert dev.receive(EXPRESS_LEGACY) == hx("a5 5a 54 00 00 40 82")  # the stream recovers


def test_unknown_commands_are_ignored() -> None:
    dev = scanning()
    assert dev.receive(hx("a5 33") + rp.encode_request(0x85, hx("01 02 03 04"))) == b""
    assert dev.counters["unknown_command"] == 2
    assert dev.mode == "scan"


def test_partial_request_dropped_on_timeout() -> None:
    dev = device()
    assert dev.receive(hx("a5 84 24 70")) == b""
    dev.drop_partial_request()
    assert dev.counters["truncated"] == 1
    assert dev.receive(INFO)[:7] == hx("a5 5a 14 00 00 00 04")


def replies_are_well_formed(reply: bytes) -> bool:
    """Every reply is a descriptor followed by exactly its declared single body,
    or a multiple-response descriptor (scan start) with nothing after it."""
    pos = 0
    while pos < len(reply):
        size, mode, _ = rp.decode_descriptor(reply[pos : pos + 7])
        pos += 7 + (size if mode == rp.SEND_SINGLE else 0)
    return pos == len(reply)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.binary(max_size=40), max_size=8))
def test_random_bytes_never_crash_the_device(chunks: list[bytes]) -> None:
    dev = device()
    dev.set_motor(True)
    for chunk in chunks:
        reply = dev.receive(chunk)
        assert replies_are_well_formed(reply)
        if dev.rebooting:
            dev.finish_reset()
        dev.encode_revolution(uniform(40))
    assert all(v >= 0 for v in dev.counters.values())


@settings(max_examples=200, deadline=None)
@given(
    noise=st.binary(max_size=20).map(lambda b: b.replace(b"\xa5", b"")),
    cmd=st.sampled_from([0x82, 0x84, 0xF0, 0xFF, 0x85]),
    payload=st.binary(min_size=1, max_size=40),
    flip=st.integers(1, 255),
)
def test_a_bad_checksum_request_never_gets_a_reply(noise, cmd, payload, flip) -> None:
    request = bytearray(rp.encode_request(cmd, payload))
    request[-1] ^= flip
    dev = device()
    assert dev.receive(noise + bytes(request)) == b""
    assert dev.counters["bad_checksum"] == 1 and dev.mode == "idle"


# -- device states -------------------------------------------------------------------


def test_stop_is_silent_and_ends_the_stream() -> None:
    dev = scanning()
    assert dev.encode_revolution(uniform(10))
    assert dev.receive(STOP) == b""
    assert dev.mode == "idle"
    assert dev.encode_revolution(uniform(10)) == b""


def test_any_request_interrupts_a_scan() -> None:
    dev = scanning()
    session = dev.session
    assert dev.receive(HEALTH)[:7] == hx("a5 5a 03 00 00 00 06")
    assert dev.mode == "idle" and dev.session != session
    # ...but MOTOR_PWM (the rplidar package's motor_speed setter) does not.
    dev = scanning()
    dev.receive(rp.encode_request(rp.CMD_SET_MOTOR_PWM, struct.pack("<H", 500)))
    assert dev.mode == "scan"


def test_reset_reboots_then_prints_the_banner() -> None:
    dev = scanning()
    assert dev.receive(hx("a5 40") + INFO) == b""  # no descriptor; the rest is lost
    assert dev.rebooting and dev.mode == "idle"
    assert dev.receive(INFO) == b""
    banner = dev.finish_reset()
    assert banner == b"RP LIDAR System.\r\nFirmware Ver 1.29 - rtm, HW Ver 7\r\nModel: 18\r\n"
    assert dev.counters["ignored_rebooting"] == 4
    assert dev.receive(INFO)[:7] == hx("a5 5a 14 00 00 00 04")


def test_motor_off_means_no_samples_unless_forced() -> None:
    dev = device()
    dev.receive(SCAN)
    assert dev.encode_revolution(uniform(10)) == b""  # waiting for a stable rotation
    dev.set_motor(True)
    assert len(dev.encode_revolution(uniform(10))) == 50
    forced = device()
    forced.receive(hx("a5 21"))
    assert len(forced.encode_revolution(uniform(10))) == 50


def test_motor_pwm_switches_the_motor_last_writer_wins() -> None:
    dev = device()
    dev.receive(rp.encode_request(rp.CMD_SET_MOTOR_PWM, struct.pack("<H", 660)))
    assert dev.motor_on and dev.pwm == 660
    dev.receive(rp.encode_request(rp.CMD_SET_MOTOR_PWM, struct.pack("<H", 0)))
    assert not dev.motor_on
    dev.set_motor(True)
    assert dev.motor_on
    bare_a1 = device(pwm_controls_motor=False)
    bare_a1.set_motor(True)
    bare_a1.receive(rp.encode_request(rp.CMD_SET_MOTOR_PWM, struct.pack("<H", 0)))
    assert bare_a1.motor_on and bare_a1.pwm == 0


def test_protection_stop_refuses_scans_until_reset() -> None:
    dev = device()
    dev.set_health(rp.HEALTH_ERROR, 0x0004)
    assert dev.receive(HEALTH) == hx("a5 5a 03 00 00 00 06 02 04 00")
    assert dev.receive(SCAN) == b"" and dev.counters["refused_scan"] == 1
    dev.receive(hx("a5 40"))
    dev.finish_reset()
    assert dev.receive(SCAN) == hx("a5 5a 05 00 00 40 81")
    stuck = device()
    stuck.set_health(rp.HEALTH_ERROR, 0x0004, persists=True)
    stuck.receive(hx("a5 40"))
    stuck.finish_reset()
    assert stuck.receive(SCAN) == b""


def test_samples_per_revolution_follow_the_sample_time() -> None:
    dev = device()
    assert dev.samples_per_revolution(5.5) == 358  # 1e6 / (508 us * 5.5 Hz)
    assert dev.samples_per_packet == 1
    dev.receive(EXPRESS_LEGACY)
    assert dev.samples_per_revolution(5.5) == 716
    assert dev.samples_per_packet == 32


def test_serial_number_must_be_16_bytes() -> None:
    with pytest.raises(ValueError):
        rp.RplidarDevice(serial_number=b"short")
