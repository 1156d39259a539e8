"""The stream policy alone: no thread, no port, a fake clock, the real device codecs."""

from __future__ import annotations

import subprocess
import sys

import pytest

from harness.devices import ldlidar as ld
from harness.devices import rplidar as rp
from harness.devices import rplidar_scans as scans
from harness.devices.ldlidar import LdlidarDevice
from harness.devices.revolution import Sample
from harness.devices.rplidar import RplidarDevice
from harness.serial_line.stats import ServerCounts
from harness.serial_line.stream_policy import StreamPolicy, no_return


def revolution(n: int, distance: float = 1000.0) -> list[Sample]:
    return [Sample(360.0 * i / n, distance + i, 40) for i in range(n)]


def scanning_a1() -> RplidarDevice:
    device = RplidarDevice()
    device.set_motor(True)
    device.receive(rp.encode_request(rp.CMD_SCAN))
    return device


def policy(device, **options) -> tuple[StreamPolicy, ServerCounts]:
    counts = ServerCounts()
    return StreamPolicy(device, counts, **options), counts


def drain(p: StreamPolicy, now: float) -> list:
    """Write everything queued at `now`, every byte taken: the revolutions finished."""
    done = p.consumed(len(p.stream), len(p.stream), now, 0)
    return [done] if done is not None else []


def test_lockstep_extra_sends_each_revolution_whole_then_its_start_marker() -> None:
    device = scanning_a1()
    p, counts = policy(device)
    r0, r1 = revolution(20), revolution(20, 2000.0)
    p.advance(0.0, (r0, 0, 0.1, 1))
    marker = scans.encode_standard([no_return(r0[0])])
    assert bytes(p.stream) == scans.encode_standard(r0) + marker
    assert p.marker_sent and p.marker_size == 1
    (sent,) = drain(p, 0.01)
    assert (sent.tick, sent.push_id, sent.repeat) == (0, 1, False)
    p.advance(0.02, (r1, 1, 0.1, 2))
    assert bytes(p.stream) == scans.encode_standard(r1) + scans.encode_standard([no_return(r1[0])])
    assert (counts.revolutions_sent, counts.markers_sent, counts.revolutions_whole) == (2, 2, 1)


def test_lockstep_replace_leaves_out_what_the_marker_stood_for() -> None:
    device = scanning_a1()
    p, _ = policy(device, next_start="replace")
    r0, r1 = revolution(20), revolution(20, 2000.0)
    p.advance(0.0, (r0, 0, 0.1, 1))
    drain(p, 0.0)
    p.advance(0.0, (r1, 1, 0.1, 2))
    nodes = scans.decode_standard_nodes(bytes(p.stream))
    assert [s for s, _ in nodes[:-1]] == scans.decode_standard(scans.encode_standard(r1[1:]))
    assert not any(start for _, start in nodes[:-1])  # its start flag went with the marker


def test_ld06_marker_completes_the_open_packet() -> None:
    """450 samples leave 6 in the encoder: the marker is the 6 that close that packet."""
    p, _ = policy(LdlidarDevice(), next_start="replace")
    assert p.unit == 12
    p.advance(0.0, (revolution(450), 0, 0.1, 1))
    assert p.marker_size == 6 and len(p.stream) % ld.PACKET_LEN == 0
    drain(p, 0.0)
    p.advance(0.0, (revolution(450), 1, 0.1, 2))
    assert p.marker_size == 12  # 444 sent after the 6 replaced: 37 packets, then a whole one
    samples, bad = ld.decode_packets(bytes(p.stream))
    assert bad == 0 and len(samples) == 444 + 12


def test_not_scanning_drops_the_revolution_and_queues_nothing() -> None:
    p, counts = policy(RplidarDevice())
    p.advance(0.0, (revolution(10), 0, 0.1, 1))
    assert not p.stream and counts.revolutions_dropped == 1 and counts.markers_sent == 0


def test_motor_off_is_told_once_a_streak() -> None:
    device = RplidarDevice()
    device.receive(rp.encode_request(rp.CMD_SCAN))  # the motor never started
    told = []
    p, counts = policy(device, tell=told.append)
    for k in range(3):
        p.advance(0.0, (revolution(10), k, 0.1, k + 1))
    assert counts.motor_off_revolutions == 3
    assert [e.kind for e in told] == ["motor_off"]


def test_a_scan_that_ends_makes_the_queued_stream_stale() -> None:
    device = scanning_a1()
    p, counts = policy(device)
    p.advance(0.0, (revolution(50), 0, 0.1, 1))
    queued = len(p.stream)
    p.device_changed()
    assert len(p.stream) == queued  # nothing changed: nothing dropped
    device.receive(rp.encode_request(rp.CMD_STOP))
    p.device_changed()
    assert not p.stream and counts.stream_bytes_dropped == queued
    assert counts.revolutions_cut == 1


def test_realtime_waits_for_the_slot_and_marks_an_underrun() -> None:
    device = scanning_a1()
    p, counts = policy(device, mode="realtime", period_s=0.1)
    r0 = revolution(10)
    assert p.slot_open(0.0)
    p.advance(0.0, (r0, 0, 0.1, 1))
    assert bytes(p.stream) == scans.encode_standard(r0)  # no marker: the next follows on its own
    drain(p, 0.05)
    assert not p.slot_open(0.05) and p.next_action_at(0.05, pushed=True, idling=False) == 0.1
    p.advance(0.1, None)  # the slot came, nothing new: close the revolution
    assert counts.underruns == 1 and bytes(p.stream) == scans.encode_standard([no_return(r0[0])])


def test_continuous_realtime_repeats_half_a_period_after_the_marker() -> None:
    device = scanning_a1()
    p, counts = policy(device, mode="realtime", period_s=0.1, continuous=True)
    p.advance(0.0, (revolution(10), 0, 0.1, 1))
    drain(p, 0.01)
    p.advance(0.1, None)  # the marker
    drain(p, 0.1)
    assert p.next_action_at(0.1, pushed=False, idling=False) == pytest.approx(0.15)
    p.advance(0.12, None)
    assert not p.stream
    p.advance(0.151, None)
    assert counts.revolutions_repeated == 1 and p.stream
    (sent,) = drain(p, 0.16)
    assert sent.repeat and sent.push_id is None


def test_continuous_lockstep_idle_stream_repeats_every_period() -> None:
    device = scanning_a1()
    p, counts = policy(device, continuous=True, next_start="replace")
    room = revolution(10, 0.0)
    p.advance(0.0, None, idle_request=(room, 0.2), idling=True)
    assert counts.revolutions_repeated == 1
    drain(p, 0.0)
    assert p.next_action_at(0.0, pushed=False, idling=True) == pytest.approx(0.2)
    p.advance(0.1, None, idling=True)
    assert not p.stream
    p.advance(0.2, None, idling=True)
    assert counts.revolutions_repeated == 2


def test_lockstep_timestamps_come_from_the_tick_not_the_clock() -> None:
    """Same pushes, same bytes, whatever the time they were sent at."""
    streams = []
    for now in (0.0, 123.4):
        p, _ = policy(LdlidarDevice(), period_s=0.1)
        p.advance(now, (revolution(450), 3, 0.1, 1))
        streams.append(bytes(p.stream))
    assert streams[0] == streams[1]


def test_the_policy_imports_no_serial_rclpy_or_pybullet() -> None:
    code = (
        "import sys, harness.serial_line.stream_policy\n"
        "print(' '.join(m for m in ('serial', 'rclpy', 'pybullet') if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ""
