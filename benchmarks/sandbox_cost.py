"""What the students' sandbox costs: a class graded with and without it, alternating.

    python benchmarks/sandbox_cost.py [--students 10] [--repeats 3] [--workers 2]
        [--scenarios approach_wall,out_of_range]

The class: STUDENTS single-file nodes (the test suite's student node, correct
variant), graded on SCENARIOS with `grade --no-audit`, once in the sandbox
(the default) and once with `--no-sandbox`, REPEATS times, alternating, in
the same minutes. Prints the median wall time of each, their difference per
student, and the ratio. Speed is measured here, never asserted in tests
(docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(REPO / "tests")]  # the tests' helpers
COMMAND = [sys.executable, "-m", "harness.cli"]


def make_class(folder: Path, students: int) -> Path:
    from cluster_nodes import variant_source

    for i in range(students):
        (folder / f"s{i:02d}").mkdir(parents=True)
        (folder / f"s{i:02d}" / "lidar_node.py").write_text(variant_source("correct"))
    return folder


def graded(classroom: Path, out: Path, workers: int, scenarios: str, *extra: str) -> float:
    started = time.perf_counter()
    done = subprocess.run(
        [*COMMAND, "grade", str(classroom), "--out", str(out), "--workers", str(workers)]
        + ["--scenario", scenarios, "--no-audit", *extra],
        capture_output=True,
        text=True,
        timeout=1800,
    )
    wall = time.perf_counter() - started
    if done.returncode != 0 or "passed" not in done.stdout:
        sys.exit(f"grade failed:\n{done.stdout}\n{done.stderr}")
    return wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--students", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--scenarios", default="approach_wall,out_of_range")
    args = parser.parse_args()
    walls: dict[str, list[float]] = {"sandbox": [], "no sandbox": []}
    with tempfile.TemporaryDirectory() as tmp:
        classroom = make_class(Path(tmp) / "class", args.students)
        for i in range(args.repeats):
            for how, extra in (("sandbox", ()), ("no sandbox", ("--no-sandbox",))):
                out = Path(tmp) / f"grades-{i}-{how.replace(' ', '-')}"
                walls[how].append(graded(classroom, out, args.workers, args.scenarios, *extra))
    boxed, plain = (statistics.median(walls[k]) for k in ("sandbox", "no sandbox"))
    print(
        f"{args.students} students, {args.scenarios}, {args.workers} workers, medians of "
        f"{args.repeats}: sandbox {boxed:.1f} s, no sandbox {plain:.1f} s, "
        f"{(boxed - plain) / args.students:+.2f} s per student, x{boxed / plain:.2f} "
        f"(all: {walls})"
    )


if __name__ == "__main__":
    main()
