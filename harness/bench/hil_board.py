"""Stage 'hil': a whole suite in real time over the virtual board, and its gaps.

``fossbot-hil run --link rplidar --board-command DRIVER`` from spawn to exit,
as a board's own software is run: the emulated A1 streams in real time at
each scenario's rate to the bundled board driver on a pty (started as the
board's software, as the FOSSBot v2's agent and bridge are: the device never
waits for the harness), for every shipped scenario in one device session,
and a fresh node under test answers each scenario (the next one started
ahead, on topics of its own); each answer is waited for up to 5 s, as the
whole-run tests wait, so a loaded machine's slow answer is not a failure.
Between two scenarios the device keeps streaming; ``gap_s`` in summary.json
is the time from one scenario's last tick to the next one's first
(``BoardLink``). ``hil_gap_median_s`` is their median (issue 41: at most
1 s), ``hil_suite_s`` the whole run. A quick bench runs two short scenarios
(one gap).
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
from pathlib import Path

from harness.bench.stage import StageResult
from harness.bench.suite_commands import cli_wall_s
from harness.errors import HarnessError
from harness.links.kinds import default_serial_link

QUICK_SUITE = ("approach_wall", "reverse_to_wall")  # short, and one gap between them
ANSWER_WAIT_S = 5.0  # --timeout, as the whole-run tests give a real-time board
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
        board = ("--board-command", DRIVER, "--timeout", f"{ANSWER_WAIT_S:g}")
        link = ("--link", default_serial_link())
        wall_s = cli_wall_s([*scenarios, *link, *board, "--out", str(out)])
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
