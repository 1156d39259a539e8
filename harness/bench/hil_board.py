"""Stage 'hil': a whole suite in real time over the virtual board, and its gaps.

``fossbot-hil run --link rplidar --realtime`` from spawn to exit: the emulated
A1 streams at each scenario's rate to the bundled board driver on a pty, for
every shipped scenario in one device session, and a fresh node under test
answers each scenario (the next one started ahead, on topics of its own).
Between two scenarios the device keeps streaming; ``gap_s`` in summary.json
is the time from one scenario's last tick to the next one's first
(``BoardLink``). ``hil_gap_median_s`` is their median (issue 41: at most
1 s), ``hil_suite_s`` the whole run. A quick bench runs two short scenarios
(one gap).
"""

from __future__ import annotations

import json
import statistics
import tempfile
from pathlib import Path

from harness.bench.stage import StageResult
from harness.bench.suite_commands import cli_wall_s
from harness.errors import HarnessError

QUICK_SUITE = ("approach_wall", "reverse_to_wall")  # short, and one gap between them


def hil_gaps(summary: Path) -> list[float]:
    """The gaps a run's summary.json gives, in scenario order (the first has none)."""
    entries = json.loads(summary.read_text(encoding="utf-8"))["scenarios"]
    return [float(e["gap_s"]) for e in entries if e.get("gap_s") is not None]


def measure_hil(scenarios: tuple[str, ...] = ()) -> StageResult:
    """One real-time suite over the virtual board (`scenarios`, default every shipped one)."""
    with tempfile.TemporaryDirectory(prefix="fossbot-hil-bench-hil-") as tmp:
        out = Path(tmp) / "report"
        wall_s = cli_wall_s([*scenarios, "--link", "rplidar", "--realtime", "--out", str(out)])
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
