"""Re-inject a recorded scan stream into the software under test and judge it.

A fossbot-hil recording carries its threshold and fault noise, so a replay
is judged exactly as the original run was; a robot's rosbag2 needs the
threshold given. Poses come along when the recording has them.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable, Iterator
from dataclasses import replace

from harness.errors import ConfigError
from harness.faults.link import NO_LINK_FAULTS, LinkFaults
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult, TickRecord
from harness.links.base import Link, LinkOptions
from harness.option_names import named
from harness.record import RecordedScans
from harness.runner.frames import Frame, check_link_faults, judge_frames
from harness.runner.scenario_run import with_link


def _recorded_float(recording: RecordedScans, key: str) -> float | None:
    text = recording.run.get(key)
    try:
        value = float(text) if text is not None else None
    except ValueError:
        return None
    return value if value is not None and math.isfinite(value) else None


def replay_threshold(recording: RecordedScans, threshold: float | None) -> float:
    """The given threshold, else the recorded run's; a robot's bag needs one given."""
    if threshold is not None:
        return threshold
    recorded = _recorded_float(recording, "threshold")
    if recorded is None or recorded <= 0:
        raise ConfigError(
            f"{recording.source}: the recording does not say its threshold; "
            f"give {named('threshold')} M"
        )
    return recorded


def scan_rate_hz(recording: RecordedScans) -> float:
    """The recorded scan rate (median period), for links that pace or emulate a device."""
    periods = [b - a for a, b in zip(recording.times, recording.times[1:], strict=False) if b > a]
    if periods:
        return 1.0 / statistics.median(periods)
    scan_time = recording.scans[0].scan_time
    return 1.0 / scan_time if scan_time > 0 else 10.0


def frames(recording: RecordedScans) -> Iterator[Frame]:
    poses = recording.poses or [(0.0, 0.0, 0.0)] * len(recording.scans)
    rows = zip(recording.times, recording.scans, poses, strict=True)
    for tick, (t, scan, (x, y, yaw)) in enumerate(rows):
        yield Frame(tick, t, x, y, yaw, scan)


def replay(
    recording: RecordedScans,
    link_name: str,
    options: LinkOptions,
    *,
    threshold: float | None = None,
    status_pattern: str | None = None,
    warning_when_clear: str | None = None,
    on_tick: Callable[[TickRecord], None] | None = None,
    link_faults: LinkFaults = NO_LINK_FAULTS,
    seed: int | None = None,
) -> RunResult:
    """Send every recorded scan through the named link, in lockstep, and judge each.

    `link_faults` (delay, drop, duplicate, reorder, stale stamps, line
    faults) act on the recorded scans as on simulated ones, drawn from
    `seed` (default: the recording's).
    """
    threshold = replay_threshold(recording, threshold)
    noise_sigma = _recorded_float(recording, "noise_sigma") or 0.0
    name = recording.run.get("scenario") or f"replay of {recording.source}"
    if seed is None:
        seed_text = recording.run.get("seed", "0")
        seed = int(seed_text) if seed_text.isdigit() else 0  # foreign metadata: no seed
    faults = recording.run.get("faults", "recorded")
    if link_faults:
        faults = f"{faults}; link: {link_faults.describe()}"

    def body(link: Link) -> RunResult:
        check_link_faults(link_faults, link)
        opening = time.perf_counter()
        link.open()
        started = time.perf_counter()
        rule = warning_when_clear or "optional"
        oracle = Oracle(
            threshold,
            noise_sigma=noise_sigma,
            status_pattern=status_pattern,
            warning_required_when_clear=rule == "required",
        )
        replayed = RunResult(
            name, link.name, seed, threshold, faults, noise_sigma, warning_rule=rule
        )
        replayed.startup_s = started - opening
        judge_frames(
            frames(recording), link, oracle, replayed, on_tick=on_tick, link_faults=link_faults
        )
        replayed.wall_s = time.perf_counter() - started
        return replayed

    def not_started(reason: str, diagnostics: str) -> RunResult:
        row = (name, link_name, seed, threshold, faults, noise_sigma)
        return RunResult(*row, error=reason, diagnostics=diagnostics)

    options = replace(options, threshold=threshold, scan_rate_hz=scan_rate_hz(recording))
    return with_link(link_name, options, body, not_started)
