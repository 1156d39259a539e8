"""The bench's figures from its stages, and the issue's targets (pure).

One flat dictionary of named figures (the keys ``fossbot-hil bench --json``
prints), the ratio of each stage to the ray-casting floor, the real-time
factors, and each target with whether it was met.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from harness.bench.stage import StageResult
from harness.links.kinds import INPROCESS, ROS2

__all__ = [
    "GRADE_KEYS", "HIL_KEYS", "REQUIRED_KEYS", "STUDENT_SPLIT_KEYS", "SUITE_KEYS", "TARGETS",
    "OVERHEAD_FORMULA", "Target", "check_targets", "figures",
]  # fmt: skip

#: The keys issue 7 asks `bench --json` for; each is a number, or null when its stage did not run.
REQUIRED_KEYS = (
    "raycast_scans_per_s", "inprocess_scans_per_s", "ros2_lockstep_scans_per_s",
    "ros2_round_trip_ms_median", "ros2_round_trip_ms_p99", "overhead_ratio", "node_startup_s",
    "lab_suite_wall_s", "serial_lockstep_scans_per_s", "serial_rate_error_pct",
    "serial_jitter_p99_ms", "peak_rss_mb",
)  # fmt: skip

#: Grading a class (issue 41): a class of correct script students through the default
#: suite, and the same students' runs back to back.
GRADE_KEYS = (
    "grade_s", "grade_per_student_s", "grade_students", "grade_workers", "grade_runs_s",
    "grade_ratio", "grade_runs_out_s", "grade_ratio_out",
)  # fmt: skip

#: HIL without gaps (issue 41): a real-time suite over the virtual board, and the gaps
#: between its scenarios (the device streams on).
HIL_KEYS = ("hil_suite_s", "hil_gap_median_s", "hil_gap_min_s", "hil_gap_max_s", "hil_gaps")

#: The edit-run loop (issue 13): the shipped suite as a user runs it, and its split.
SUITE_KEYS = (
    "suite_s", "suite_startup_s", "suite_ticking_s", "suite_stop_s", "suite_process_s",
    "suite_inprocess_s", "suite_scenarios", "suite_scans", "suite_runs_s",
    # The same suite against the lab's package in a colcon workspace
    # (a student's node), and with the inprocess link; the three runs alternated.
    "student_build_s", "student_suite_s", "student_suite_runs_s", "student_suite_ratio",
    "inprocess_suite_s", "inprocess_suite_runs_s", "inprocess_suite_ratio",
)  # fmt: skip

#: The workspace node's suite split like the bundled one's (null with `--quick`).
STUDENT_SPLIT_KEYS = (
    "student_suite_startup_s", "student_suite_ticking_s", "student_suite_stop_s",
    "student_suite_process_s", "student_suite_inprocess_s",
)  # fmt: skip

OVERHEAD_FORMULA = (
    "per ROS 2 round: (lockstep s/scan - raycast s/scan measured just before the round "
    "- the round's median round trip s) / (raycast s/scan + median round trip s); "
    "the median of the rounds"
)

#: Throughput stages, by the name their figures carry.
_THROUGHPUT = {
    "raycast": "raycast", "synthesis": "synthesis", INPROCESS: INPROCESS, ROS2: "ros2_lockstep",
    "serial": "serial_lockstep",
}  # fmt: skip


@dataclass(frozen=True)
class Target:
    """A goal from the issue: `key` compared by `met` against `goal`."""

    key: str
    label: str
    goal: str
    met: Callable[[float], bool]


TARGETS = (
    Target("ros2_lockstep_scans_per_s", "ROS 2 lockstep", ">= 500 scans/s", lambda v: v >= 500),
    Target("overhead_ratio", "harness overhead per scan", "<= 25 %", lambda v: v <= 0.25),
    Target("lab_suite_wall_s", "lab trio over ROS 2", "< 5 s", lambda v: v < 5.0),
    Target("lab_suite_cli_wall_s", "lab trio, CLI from spawn", "< 5 s", lambda v: v < 5.0),
    Target("suite_s", "shipped suite over ROS 2, CLI from spawn", "<= 2.0 s", lambda v: v <= 2.0),
    Target("student_suite_ratio", "shipped suite, workspace node / bundled node",
           "<= 1.2", lambda v: v <= 1.2),
    Target("inprocess_suite_ratio", "shipped suite, bundled node / inprocess link",
           "<= 1.5", lambda v: v <= 1.5),
    Target("grade_ratio", "grading a class / its runs on the same workers",
           "<= 1.3", lambda v: v <= 1.3),
    Target("hil_gap_median_s", "real-time HIL: gap between scenarios, median",
           "<= 1 s", lambda v: v <= 1.0),
    Target("serial_rate_error_pct", "serial byte rate error", "within 1 %", lambda v: abs(v) <= 1),
    Target("serial_jitter_p99_ms", "revolution jitter p99", "< 2 ms", lambda v: v < 2.0),
)  # fmt: skip


def _extra(stage: StageResult | None, key: str) -> Any:
    return stage.extra.get(key) if stage is not None else None


def _children_peak_mb(stages: Mapping[str, StageResult]) -> float:
    """The most memory the processes of one link stage held at once (node, board driver)."""
    most = 0.0
    for name in (ROS2, "serial"):
        stage = stages.get(name)
        if stage is not None:
            peaks = (stage.extra.get("node_peak_rss_mb"), stage.extra.get("driver_peak_rss_mb"))
            most = max(most, sum(p for p in peaks if isinstance(p, (int, float))))
    return most


def figures(stages: Mapping[str, StageResult], harness_peak_rss_mb: float) -> dict[str, Any]:
    """Every named figure, None where its stage did not run; ``peak_rss_mb`` adds the most
    the child processes held at once in one link stage."""
    out: dict[str, Any] = {}
    for stage_name, prefix in _THROUGHPUT.items():
        stage = stages.get(stage_name)
        out[f"{prefix}_scans_per_s"] = stage.scans_per_s if stage else None
    raycast, ros2, serial = stages.get("raycast"), stages.get(ROS2), stages.get("serial")
    pacing, suite = stages.get("pacing"), stages.get("suite")
    out["raycast_truth_ms"] = _extra(raycast, "truth_ms")
    out["synthesis_harsh_scans_per_s"] = _extra(stages.get("synthesis"), "harsh_scans_per_s")
    out["ros2_round_trip_ms_median"] = _extra(ros2, "round_trip_ms_median")
    out["ros2_round_trip_ms_p99"] = _extra(ros2, "round_trip_ms_p99")
    out["ros2_wait_ms_median"] = _extra(ros2, "wait_ms_median")
    out["ros2_scan_ms"] = ros2.scan_s * 1000.0 if ros2 else None
    out["overhead_ratio"] = _extra(ros2, "overhead_ratio")  # each round against its own floor
    out["inprocess_cpu_ms_per_scan"] = _extra(stages.get(INPROCESS), "cpu_ms_per_scan")
    out["ros2_cpu_ms_per_scan"] = _extra(ros2, "cpu_ms_per_scan")
    out["ros2_node_cpu_ms_per_scan"] = _extra(ros2, "node_cpu_ms_per_scan")
    out["serial_cpu_ms_per_scan"] = _extra(serial, "cpu_ms_per_scan")
    out["serial_node_cpu_ms_per_scan"] = _extra(serial, "node_cpu_ms_per_scan")
    out["serial_driver_cpu_ms_per_scan"] = _extra(serial, "driver_cpu_ms_per_scan")
    out["node_startup_s"] = _extra(ros2, "startup_s")
    out["serial_startup_s"] = _extra(serial, "startup_s")
    out["lab_suite_wall_s"] = suite.seconds if suite else None
    out["lab_suite_cli_wall_s"] = _extra(suite, "cli_wall_s")
    for key in (*SUITE_KEYS, *STUDENT_SPLIT_KEYS):
        out[key] = _extra(suite, key)
    for key in GRADE_KEYS:
        out[key] = _extra(stages.get("grade"), key)
    for key in HIL_KEYS:
        out[key] = _extra(stages.get("hil"), key)
    out["serial_rate_error_pct"] = _extra(pacing, "reader_rate_error_pct")
    out["serial_jitter_p99_ms"] = _extra(pacing, "reader_jitter_p99_ms")
    out["serial_pacer_rate_error_pct"] = _extra(pacing, "pacer_rate_error_pct")
    out["serial_pacer_jitter_p99_ms"] = _extra(pacing, "pacer_jitter_p99_ms")
    out["serial_jitter_median_ms"] = _extra(pacing, "reader_jitter_median_ms")
    out["serial_jitter_max_ms"] = _extra(pacing, "reader_jitter_max_ms")
    out["serial_pacer_jitter_median_ms"] = _extra(pacing, "pacer_jitter_median_ms")
    children = _children_peak_mb(stages)
    out["peak_rss_mb"] = harness_peak_rss_mb + children
    out["peak_rss_mb_harness"] = harness_peak_rss_mb
    out["peak_rss_mb_children"] = children if children else None
    out["node_peak_rss_mb"] = _extra(ros2, "node_peak_rss_mb")
    out["serial_driver_peak_rss_mb"] = _extra(serial, "driver_peak_rss_mb")
    floor = raycast.scan_s if raycast else None
    out["ratio_to_raycast"] = {
        prefix: (stage.scan_s / floor if floor and stage else None)
        for name, prefix in _THROUGHPUT.items()
        if name != "raycast"
        for stage in [stages.get(name)]
    }
    out["real_time_factor"] = {
        prefix: stage.real_time_factor if stage else None
        for name, prefix in _THROUGHPUT.items()
        for stage in [stages.get(name)]
    }
    return out


def check_targets(values: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Each target with the measured value and whether it was met (None: not measured)."""
    return [
        {
            "key": target.key,
            "label": target.label,
            "target": target.goal,
            "value": value,
            "met": None if value is None else bool(target.met(value)),
        }
        for target in TARGETS
        for value in [values.get(target.key)]
    ]
