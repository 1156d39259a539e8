"""Stage 'hil': a whole suite in real time over the virtual board, and its gaps.

``fossbot-hil run --link rplidar --board-command DRIVER`` from spawn to exit:
the emulated A1 streams in real time to the bundled driver started as the
board's software (the device never waits for the harness), every scenario in
one device session. Between scenarios the device keeps streaming; their
gaps (``gap_s`` in summary.json) are what issue 41 bounds (median <= 1 s).
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
from pathlib import Path

from harness.bench.stage import StageResult
from harness.bench.suite_commands import cli_args, cli_wall_s
from harness.errors import HarnessError
from harness.links.kinds import default_serial_link

QUICK_SUITE = ("approach_wall", "reverse_to_wall")  # short, and one gap between them
ANSWER_WAIT_S = 5.0  # the scan timeout, as the whole-run tests give a real-time board
# The bundled driver as a board's own software ({port}: the emulated device's path);
# its defaults are the v2 bridge's mapping, as the robot model's mount wants.
DRIVER = f"{sys.executable} -m harness.board_driver.rplidar_node --ros-args -p port:={{port}}"


def hil_gaps(summary: Path) -> list[float]:
    """The gaps a run's summary.json gives, in scenario order (the first has none)."""
    entries = json.loads(summary.read_text(encoding="utf-8"))["scenarios"]
    return [float(e["gap_s"]) for e in entries if e.get("gap_s") is not None]


def measure_hil(scenarios: tuple[str, ...] = ()) -> StageResult:
    """One real-time suite over the virtual board (`scenarios`, default every shipped one)."""
    with tempfile.TemporaryDirectory(prefix="fossbot-hil-bench-hil-") as tmp:
        out = Path(tmp) / "report"
        link = cli_args(link=default_serial_link(), board_commands=DRIVER, out=str(out))
        wall_s = cli_wall_s([*scenarios, *link, *cli_args(scan_timeout=f"{ANSWER_WAIT_S:g}")])
        gaps = hil_gaps(out / "summary.json")
    if not gaps:
        raise HarnessError("the real-time suite over the virtual board reported no gap")
    extra: dict[str, float | int | str | None] = {
        "hil_suite_s": wall_s,
        "hil_gap_median_s": statistics.median(gaps),
        "hil_gap_min_s": min(gaps),
        "hil_gap_max_s": max(gaps),
        "hil_gaps": len(gaps),
    }
    return StageResult("hil", 0, wall_s, 0.0, extra)
