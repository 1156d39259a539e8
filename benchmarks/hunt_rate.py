"""How fast `fossbot-hil hunt` runs, and how many runs it needs to find planted mistakes.

    python benchmarks/hunt_rate.py [--repeats 3] [--rate-runs 40] [--seeds 5]
        [--mistakes rounded_before_comparing,angle_without_angle_min,...]

1. Runs per second: a correct node (the audit's control, over ROS 2) hunted for
   RATE_RUNS runs on an embedded cluster of 1 worker and of 2, alternating,
   REPEATS times; the median of hunt.json's runs / seconds (the cluster's start
   is not counted).
2. Runs to find: each planted mistake (the audit's mutant node) hunted with
   seeds 0..SEEDS-1, budget 150, 2 workers, no shrinking; the median and the
   range of hunt.json's found_at_run.

Speed is measured here, never asserted in tests (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

COMMAND = [sys.executable, "-m", "harness.cli"]
MISTAKES = (
    "rounded_before_comparing",
    "angle_without_angle_min",
    "zero_as_obstacle",
    "crash_when_nothing_in_range",
)


def hunted(out: Path, mistake: str, *options: str) -> dict:
    from harness.audit.mutants import mutant_command

    done = subprocess.run(
        [*COMMAND, "hunt", "--node", mutant_command(mistake), "--out", str(out), *options],
        capture_output=True,
        text=True,
        timeout=3600,
    )
    if done.returncode not in (0, 1):
        sys.exit(f"hunt failed:\n{done.stdout}\n{done.stderr}")
    return json.loads((out / "hunt.json").read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--rate-runs", type=int, default=40)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--mistakes", default=",".join(MISTAKES))
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        rates: dict[int, list[float]] = {1: [], 2: []}
        for repeat in range(args.repeats):
            for workers in (1, 2):
                said = hunted(
                    root / f"rate{workers}-{repeat}",
                    "correct",
                    *("--budget", str(args.rate_runs), "--workers", str(workers)),
                )
                rates[workers].append(said["runs"] / said["seconds"])
        for workers, values in rates.items():
            shown = ", ".join(f"{v:.2f}" for v in values)
            print(f"{workers} worker(s): {statistics.median(values):.2f} runs/s ({shown})")
        for mistake in args.mistakes.split(","):
            found = []
            for seed in range(args.seeds):
                said = hunted(
                    root / f"{mistake}-{seed}",
                    mistake,
                    *("--budget", "150", "--workers", "2", "--seed", str(seed)),
                    *("--shrink-budget", "0"),
                )
                found.append(said["found_at_run"] or 151)
            print(
                f"{mistake}: median {statistics.median(found):g} runs to find "
                f"(seeds 0..{args.seeds - 1}: {', '.join(map(str, found))}; 151 = not found)"
            )


if __name__ == "__main__":
    main()
