"""Slamtec RPLIDAR A1M8: the device's side of its serial protocol, as pure code.

``RplidarDevice`` is a state machine fed the host's bytes: it returns the
immediate replies and, once scanning, encodes each revolution
(``rplidar_scans``); the front end paces the bytes and drives DTR. The
host side of requests is here too (``encode_request``,
``decode_descriptor``). Facts and sources: docs/devices.md.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass

from harness.devices.events import DeviceEvent, Listener
from harness.devices.ldlidar import starts_like_command
from harness.devices.protocol import DeviceDefaults
from harness.devices.revolution import Sample
from harness.devices.rplidar_scans import (
    CAPSULE_LEN,
    NODE_LEN,
    SAMPLES_PER_CAPSULE,
    encode_capsule,
    encode_standard,
    xor_all,
)
from harness.option_names import worded

# -- wire constants (Slamtec protocol v2.x, sl_lidar_cmd.h) --------------------

BAUD = 115200
SYNC = 0xA5  # first byte of every request
ANSWER_SYNC = b"\xa5\x5a"  # first two bytes of every response descriptor
CMD_HAS_PAYLOAD = 0x80  # set in the command byte of requests carrying a payload

CMD_STOP = 0x25
CMD_SCAN = 0x20
CMD_FORCE_SCAN = 0x21
CMD_RESET = 0x40
CMD_GET_INFO = 0x50
CMD_GET_HEALTH = 0x52
CMD_GET_SAMPLERATE = 0x59
CMD_EXPRESS_SCAN = 0x82
CMD_GET_LIDAR_CONF = 0x84
CMD_SET_MOTOR_PWM = 0xF0
CMD_GET_ACC_BOARD_FLAG = 0xFF

COMMAND_NAMES: dict[int, str] = {
    CMD_STOP: "STOP",
    CMD_SCAN: "SCAN",
    CMD_FORCE_SCAN: "FORCE_SCAN",
    CMD_RESET: "RESET",
    CMD_GET_INFO: "GET_INFO",
    CMD_GET_HEALTH: "GET_HEALTH",
    CMD_GET_SAMPLERATE: "GET_SAMPLERATE",
    CMD_EXPRESS_SCAN: "EXPRESS_SCAN",
    CMD_GET_LIDAR_CONF: "GET_LIDAR_CONF",
    CMD_SET_MOTOR_PWM: "MOTOR_PWM",
    CMD_GET_ACC_BOARD_FLAG: "GET_ACC_BOARD_FLAG",
}

ANS_DEVINFO = 0x04
ANS_HEALTH = 0x06
ANS_SAMPLERATE = 0x15
ANS_GET_LIDAR_CONF = 0x20
ANS_MEASUREMENT = 0x81
ANS_CAPSULED = 0x82
ANS_ACC_BOARD_FLAG = 0xFF

SEND_SINGLE = 0  # descriptor send mode: one response packet
SEND_MULTIPLE = 1  # descriptor send mode: a stream of response packets

CONF_SCAN_MODE_COUNT = 0x70
CONF_SCAN_MODE_US_PER_SAMPLE = 0x71
CONF_SCAN_MODE_MAX_DISTANCE = 0x74
CONF_SCAN_MODE_ANS_TYPE = 0x75
CONF_SCAN_MODE_TYPICAL = 0x7C
CONF_SCAN_MODE_NAME = 0x7F

HEALTH_OK = 0
HEALTH_WARNING = 1
HEALTH_ERROR = 2  # "Protection Stop": scan requests are refused until RESET

DESCRIPTOR_LEN = 7

# A1M8 firmware 1.29 as measured on a real unit (GET_SAMPLERATE: 508 / 254 us).
STANDARD_SAMPLE_US = 508
EXPRESS_SAMPLE_US = 254
A1_MAX_DISTANCE_M = 12.0
DEFAULT_SERIAL = b"FOSSBOT-HIL-A1M8"  # 16 bytes, obviously not a real unit's
# The protocol asks hosts to wait >= 2 ms after RESET; the banner follows the reboot.
RESET_REBOOT_S = 0.002

COUNTER_NAMES = (
    "requests",  # well-formed requests (valid checksum where there is one)
    "bad_checksum",  # payload requests dropped for a wrong checksum
    "garbage_bytes",  # bytes skipped while looking for the 0xA5 sync byte
    "unknown_command",  # well-formed requests with a command the device ignores
    "truncated",  # partial requests abandoned by the front end (inter-byte timeout)
    "bad_payload",  # known commands with a payload of the wrong size
    "unknown_conf",  # GET_LIDAR_CONF for a type or mode the device does not answer
    "unsupported_mode",  # EXPRESS_SCAN with a working mode the emulator does not stream
    "refused_scan",  # scan requests ignored in Protection Stop
    "ignored_rebooting",  # bytes that arrived while the core was rebooting
)


@dataclass(frozen=True)
class ScanMode:
    """One entry of the GET_LIDAR_CONF scan-mode table."""

    name: str
    us_per_sample: float
    max_distance_m: float
    ans_type: int  # ANS_MEASUREMENT (standard nodes) or ANS_CAPSULED (legacy express)


def default_scan_modes(
    standard_sample_us: float = STANDARD_SAMPLE_US, express_sample_us: float = EXPRESS_SAMPLE_US
) -> tuple[ScanMode, ...]:
    """The modes the emulator streams: Standard (id 0) and legacy Express (id 1).

    A real A1M8 on firmware 1.29 also lists Boost, Sensitivity and Stability,
    which stream ultra capsules (answer type 0x84) that are not emulated.
    """
    return (
        ScanMode("Standard", standard_sample_us, A1_MAX_DISTANCE_M, ANS_MEASUREMENT),
        ScanMode("Express", express_sample_us, A1_MAX_DISTANCE_M, ANS_CAPSULED),
    )


# -- host side: requests --------------------------------------------------------


def _command_name(cmd: int) -> str:
    """A request's name, or its byte for a command the device does not know."""
    return COMMAND_NAMES.get(cmd, f"0x{cmd:02X}")


def _garbage_note(data: bytes | bytearray) -> str:
    """Name bytes that are another LIDAR's (else the generic hint applies)."""
    if starts_like_command(data):
        return "an LDROBOT command frame (54 ...): an LD06/LD19 driver on an RPLIDAR; " + worded(
            "use its own device type (emulate ldlidar, {link} ldlidar)"
        )
    return ""


def encode_request(cmd: int, payload: bytes = b"") -> bytes:
    """A request as a host sends it: ``A5 cmd`` or ``A5 cmd size payload checksum``.

    A payload sets the 0x80 flag in the command byte (as the SDK does); a
    command that already has the flag gets size and checksum even when empty.
    """
    if not 0 <= cmd <= 0xFF:
        raise ValueError(f"command must be a byte, got {cmd}")
    if len(payload) > 0xFF:
        raise ValueError(f"payload is at most 255 bytes, got {len(payload)}")
    if not payload and not cmd & CMD_HAS_PAYLOAD:
        return bytes((SYNC, cmd))
    head = bytes((SYNC, cmd | CMD_HAS_PAYLOAD, len(payload))) + bytes(payload)
    return head + bytes((xor_all(head),))


def encode_descriptor(size: int, send_mode: int, data_type: int) -> bytes:
    """A response descriptor: A5 5A, then size (30 bits) | mode (2 bits) LE, then the type."""
    return ANSWER_SYNC + struct.pack("<IB", (size & 0x3FFFFFFF) | (send_mode << 30), data_type)


def decode_descriptor(data: bytes) -> tuple[int, int, int]:
    """(size, send_mode, data_type) of a 7-byte response descriptor."""
    if len(data) != DESCRIPTOR_LEN or data[:2] != ANSWER_SYNC:
        raise ValueError(f"not a response descriptor: {data.hex(' ')}")
    size_mode, data_type = struct.unpack("<IB", data[2:])
    return size_mode & 0x3FFFFFFF, size_mode >> 30, data_type


# -- the device -----------------------------------------------------------------


class RplidarDevice(DeviceDefaults):
    """An A1M8 as seen from its serial line: requests in, replies and scans out.

    Motor: the A1's adapter drives it from DTR (asserted stops it), told by
    ``set_motor``; MOTOR_PWM switches it too (last writer wins) unless
    ``pwm_controls_motor`` is False. SCAN and EXPRESS_SCAN stream nothing while
    it is off (the device waits for a stable rotation); FORCE_SCAN streams anyway.
    """

    follows_motor_line = True  # the adapter's DTR drives the motor

    def __init__(
        self,
        *,
        model: int = 0x18,
        firmware: tuple[int, int] = (1, 29),
        hardware: int = 7,
        serial_number: bytes = DEFAULT_SERIAL,
        standard_sample_us: int = STANDARD_SAMPLE_US,
        express_sample_us: int = EXPRESS_SAMPLE_US,
        scan_modes: Sequence[ScanMode] | None = None,
        typical_mode: int = 1,
        pwm_controls_motor: bool = True,
    ) -> None:
        if len(serial_number) != 16:
            raise ValueError(f"serial_number must be 16 bytes, got {len(serial_number)}")
        self.model, self.firmware, self.hardware = model, firmware, hardware
        self.serial_number = bytes(serial_number)
        self.standard_sample_us, self.express_sample_us = standard_sample_us, express_sample_us
        if scan_modes is None:
            scan_modes = default_scan_modes(standard_sample_us, express_sample_us)
        self.scan_modes = tuple(scan_modes)
        self.typical_mode, self.pwm_controls_motor = typical_mode, pwm_controls_motor
        major, minor = firmware
        # What the A1 prints (CRLF text, no descriptor) at power-up and after RESET.
        self.reset_banner = (
            f"RP LIDAR System.\r\nFirmware Ver {major}.{minor:02d} - rtm, HW Ver {hardware}\r\n"
            f"Model: {model:02x}\r\n"
        ).encode("ascii")
        self.motor_on = False
        self.pwm: int | None = None  # last MOTOR_PWM value, None if never sent
        self.health_status, self.health_error = HEALTH_OK, 0
        self.fault_persists = False  # a fault that RESET does not clear
        self.rebooting = False
        self.session = 0  # bumped whenever a scan starts or ends: stale bytes can be dropped
        self.counters: dict[str, int] = dict.fromkeys(COUNTER_NAMES, 0)
        self.requests_by_command: dict[str, int] = {}  # well-formed requests, by name
        # Told of every request and protocol error (called on the caller's thread).
        self.listener: Listener | None = None
        self._rx = bytearray()
        self._mode = "idle"
        self._forced = False
        self._express_pending: list[Sample] = []
        self._express_restart = True
        # Each command's handler is named after it: GET_INFO -> _on_get_info.
        self._handlers = {c: getattr(self, f"_on_{n.lower()}") for c, n in COMMAND_NAMES.items()}

    # -- state seen by the front end ----------------------------------------

    @property
    def mode(self) -> str:
        """ "idle", "scan" (SCAN / FORCE_SCAN) or "express" (EXPRESS_SCAN)."""
        return self._mode

    @property
    def sample_us(self) -> float:
        """Time per sample in the current (or, when idle, standard) mode."""
        return self.express_sample_us if self._mode == "express" else self.standard_sample_us

    @property
    def samples_per_packet(self) -> int:
        """Samples per unit on the wire: one node, or one 32-sample capsule in express."""
        return SAMPLES_PER_CAPSULE if self._mode == "express" else 1

    @property
    def bytes_per_sample(self) -> float:
        """Line bytes per sample in the current (or, when idle, standard) mode."""
        return CAPSULE_LEN / SAMPLES_PER_CAPSULE if self._mode == "express" else NODE_LEN

    def samples_per_revolution(self, rate_hz: float) -> int:
        """How many samples one revolution holds at this rotation rate."""
        return max(1, round(1e6 / (self.sample_us * rate_hz)))

    def set_motor(self, on: bool) -> None:
        """The motor line changed (DTR on the A1's adapter): True runs the motor."""
        self.motor_on = bool(on)

    def set_health(self, status: int, error_code: int = 0, *, persists: bool = False) -> None:
        """Inject a health state; HEALTH_ERROR is Protection Stop (scans refused)."""
        self.health_status, self.health_error, self.fault_persists = status, error_code, persists
        if status == HEALTH_ERROR:
            self._leave_scan()

    # -- bytes from the host -------------------------------------------------

    def receive(self, data: bytes) -> bytes:
        """Feed bytes from the host; return the device's immediate replies.

        Partial requests wait, bytes before 0xA5 are skipped, bad checksums and
        unknown requests are dropped silently. Any request but MOTOR_PWM ends a
        running scan: drop unsent revolution bytes when ``session`` changes.
        """
        if self.rebooting:
            self._error("ignored_rebooting", bytes(data), len(data))
            return b""
        self._rx += data
        out = bytearray()
        while (request := self._next_request()) is not None:
            out += self._handle(*request)
            if self.rebooting:  # RESET: whatever followed it dies with the core
                if self._rx:
                    self._error("ignored_rebooting", bytes(self._rx), len(self._rx))
                self._rx.clear()
                break
        return bytes(out)

    def drop_partial_request(self) -> None:
        """Abandon an incomplete request (the front end saw the line go quiet)."""
        if self._rx:
            self._error("truncated", bytes(self._rx))
            self._rx.clear()

    def finish_reset(self) -> bytes:
        """End the reboot started by RESET; returns the banner the device prints."""
        self.rebooting = False
        return self.reset_banner

    def _error(
        self, kind: str, data: bytes, count: int = 1, *, command: str = "", note: str = ""
    ) -> None:
        """Count a protocol error and tell the listener what it was about."""
        self.counters[kind] += count
        if self.listener is not None:
            self.listener(DeviceEvent(kind, data, command=command, note=note))

    def _next_request(self) -> tuple[int, bytes, bytes] | None:
        """(command, payload, the request's bytes) of the next whole request, if any."""
        rx = self._rx
        while rx:
            if rx[0] != SYNC:
                skip = rx.find(SYNC)
                skip = len(rx) if skip < 0 else skip
                self._error("garbage_bytes", bytes(rx[:skip]), skip, note=_garbage_note(rx[:skip]))
                del rx[:skip]
                continue
            if len(rx) < 2:
                return None
            cmd = rx[1]
            if cmd == SYNC:  # no command is 0xA5: the first sync byte was noise
                del rx[:1]
                self._error("garbage_bytes", bytes((SYNC,)))
                continue
            if not cmd & CMD_HAS_PAYLOAD:
                raw = bytes(rx[:2])
                del rx[:2]
                return cmd, b"", raw
            if len(rx) < 3 or len(rx) < 4 + rx[2]:
                return None
            packet = bytes(rx[: 4 + rx[2]])
            del rx[: len(packet)]
            if xor_all(packet[:-1]) != packet[-1]:
                want = xor_all(packet[:-1])
                self._error(
                    "bad_checksum",
                    packet,
                    command=_command_name(cmd),
                    note=f"checksum {packet[-1]:02X}, expected {want:02X}: request dropped",
                )
                continue
            return cmd, packet[3:-1], packet
        return None

    def _handle(self, cmd: int, payload: bytes, raw: bytes = b"") -> bytes:
        handler = self._handlers.get(cmd)
        if handler is None:
            self._error("unknown_command", raw, command=_command_name(cmd))
            return b""
        self.counters["requests"] += 1
        name = COMMAND_NAMES[cmd]
        self.requests_by_command[name] = self.requests_by_command.get(name, 0) + 1
        was = self._mode
        if cmd != CMD_SET_MOTOR_PWM:
            self._leave_scan()
        errors = sum(self.counters.values())
        reply = handler(payload)
        if self.listener is not None:
            rejected = sum(self.counters.values()) != errors  # the handler logged why
            note = "" if rejected else self._after(cmd, was)
            self.listener(DeviceEvent("request", raw, name, reply, note))
        return reply

    def _after(self, cmd: int, was: str) -> str:
        """What a request changed, in words, for the log."""
        motor = "motor on" if self.motor_on else "motor OFF: nothing streams until it runs"
        if cmd in (CMD_SCAN, CMD_EXPRESS_SCAN):
            kind = "standard nodes" if cmd == CMD_SCAN else "express capsules"
            return f"scan started ({kind}), {motor}"
        if cmd == CMD_FORCE_SCAN:
            return "scan started (standard nodes, streams whatever the motor)"
        if cmd == CMD_SET_MOTOR_PWM:
            return f"pwm {self.pwm}: {motor}"
        if cmd == CMD_RESET:
            return "rebooting; the banner follows"
        if was != "idle":
            return "scan stopped"
        return ""

    def _leave_scan(self) -> None:
        if self._mode != "idle":
            self._mode = "idle"
            self._forced = False
            self.session += 1

    def _start_scan(self, mode: str, *, forced: bool = False) -> None:
        self._mode = mode
        self._forced = forced
        self._express_pending = []
        self._express_restart = True
        self.session += 1

    # -- request handlers ------------------------------------------------------

    def _on_stop(self, payload: bytes) -> bytes:
        return b""

    def _on_reset(self, payload: bytes) -> bytes:
        self.rebooting = True
        if self.health_status == HEALTH_ERROR and not self.fault_persists:
            self.health_status, self.health_error = HEALTH_OK, 0
        return b""

    def _scan_refused(self) -> bool:
        if self.health_status == HEALTH_ERROR:
            self._error("refused_scan", b"")
            return True
        return False

    def _on_scan(self, payload: bytes, *, forced: bool = False) -> bytes:
        if self._scan_refused():
            return b""
        self._start_scan("scan", forced=forced)
        return encode_descriptor(NODE_LEN, SEND_MULTIPLE, ANS_MEASUREMENT)

    def _on_force_scan(self, payload: bytes) -> bytes:
        return self._on_scan(payload, forced=True)

    def _on_express_scan(self, payload: bytes) -> bytes:
        if len(payload) != 5:
            self._error("bad_payload", payload, command="EXPRESS_SCAN", note="want 5 bytes")
            return b""
        working_mode = payload[0]
        legacy = working_mode == 0 or (
            working_mode < len(self.scan_modes)
            and self.scan_modes[working_mode].ans_type == ANS_CAPSULED
        )
        if not legacy:
            self._error("unsupported_mode", payload, command="EXPRESS_SCAN")
            return b""
        if self._scan_refused():
            return b""
        self._start_scan("express")
        return encode_descriptor(CAPSULE_LEN, SEND_MULTIPLE, ANS_CAPSULED)

    def _on_get_info(self, payload: bytes) -> bytes:
        major, minor = self.firmware
        body = struct.pack("<BBBB", self.model, minor, major, self.hardware) + self.serial_number
        return encode_descriptor(len(body), SEND_SINGLE, ANS_DEVINFO) + body

    def _on_get_health(self, payload: bytes) -> bytes:
        body = struct.pack("<BH", self.health_status, self.health_error)
        return encode_descriptor(len(body), SEND_SINGLE, ANS_HEALTH) + body

    def _on_get_samplerate(self, payload: bytes) -> bytes:
        body = struct.pack("<HH", self.standard_sample_us, self.express_sample_us)
        return encode_descriptor(len(body), SEND_SINGLE, ANS_SAMPLERATE) + body

    def _on_get_lidar_conf(self, payload: bytes) -> bytes:
        if len(payload) < 4:
            self._error("bad_payload", payload, command="GET_LIDAR_CONF", note="want >= 4 bytes")
            return b""
        conf_type = struct.unpack_from("<I", payload)[0]
        mode_id = struct.unpack_from("<H", payload, 4)[0] if len(payload) >= 6 else 0
        data = self._conf_value(conf_type, mode_id)
        if data is None:
            note = f"type 0x{conf_type:X}, mode {mode_id}: no answer, as on a device without it"
            self._error("unknown_conf", payload, command="GET_LIDAR_CONF", note=note)
            return b""
        body = struct.pack("<I", conf_type) + data
        return encode_descriptor(len(body), SEND_SINGLE, ANS_GET_LIDAR_CONF) + body

    def _conf_value(self, conf_type: int, mode_id: int) -> bytes | None:
        if conf_type == CONF_SCAN_MODE_COUNT:
            return struct.pack("<H", len(self.scan_modes))
        if conf_type == CONF_SCAN_MODE_TYPICAL:
            return struct.pack("<H", self.typical_mode)
        per_mode = {
            CONF_SCAN_MODE_US_PER_SAMPLE: lambda m: struct.pack("<I", round(m.us_per_sample * 256)),
            CONF_SCAN_MODE_MAX_DISTANCE: lambda m: struct.pack("<I", round(m.max_distance_m * 256)),
            CONF_SCAN_MODE_ANS_TYPE: lambda m: bytes((m.ans_type,)),
            CONF_SCAN_MODE_NAME: lambda m: m.name.encode("ascii") + b"\x00",
        }
        if conf_type not in per_mode or mode_id >= len(self.scan_modes):
            return None
        return per_mode[conf_type](self.scan_modes[mode_id])

    def _on_motor_pwm(self, payload: bytes) -> bytes:
        if len(payload) != 2:
            self._error("bad_payload", payload, command="MOTOR_PWM", note="want 2 bytes")
            return b""
        self.pwm = struct.unpack("<H", payload)[0]
        if self.pwm_controls_motor:
            self.motor_on = self.pwm > 0
        return b""

    def _on_get_acc_board_flag(self, payload: bytes) -> bytes:
        body = struct.pack("<I", 0)  # no accessory board: motor speed is not PWM-controlled
        return encode_descriptor(len(body), SEND_SINGLE, ANS_ACC_BOARD_FLAG) + body

    # -- revolutions out -------------------------------------------------------

    def encode_revolution(self, samples: Sequence[Sample], *, start_ms: float = 0.0) -> bytes:
        """The bytes streamed for one revolution in the current mode (`start_ms` is not sent).

        Empty when idle, rebooting or with the motor off (but after FORCE_SCAN).
        Express samples short of a capsule wait for the next call (a capsule
        needs the next one's start angle).
        """
        if self.rebooting or self._mode == "idle":
            return b""
        if not self.motor_on and not self._forced:
            self._express_pending = []
            self._express_restart = True  # rotation unstable: the next capsule restarts
            return b""
        if self._mode == "scan":
            return encode_standard(samples)
        return self._encode_express(samples)

    def _encode_express(self, samples: Sequence[Sample]) -> bytes:
        pending = self._express_pending
        pending.extend(samples)
        out = bytearray()
        while len(pending) > SAMPLES_PER_CAPSULE:
            chunk = pending[:SAMPLES_PER_CAPSULE]
            next_start = pending[SAMPLES_PER_CAPSULE].angle_deg
            out += encode_capsule(chunk, next_start, start_flag=self._express_restart)
            self._express_restart = False
            del pending[:SAMPLES_PER_CAPSULE]
        return bytes(out)
