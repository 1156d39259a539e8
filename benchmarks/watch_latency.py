"""From saving a fix to "7 of 7 scenarios passed" on `run --watch`'s screen.

    python benchmarks/watch_latency.py [--samples 3] [--variant angle_in_degrees]

A student's script (tests/ros/student_node.py with a bug written in) runs
under `fossbot-hil run --watch --node "python3 node.py"` over ROS 2, every
shipped scenario. Each sample saves the fixed script, reads the watch's
output (a pipe: plain lines, flushed as they happen) until "7 of 7
scenarios passed", then saves the bug again and waits for that run to end.
Prints, per sample and as medians: seconds from the save to the first
verdict and to the all-passed line (as read here), and the seconds the
watch itself reports since it saw the change. Speed is measured here,
never asserted in tests (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import os
import queue
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
STUDENT = REPO / "tests" / "ros" / "student_node.py"
VARIANT_LINE = '    variant = sys.argv[1] if len(sys.argv) > 1 else "correct"'
LINE_TIMEOUT = 120.0
VERDICT = re.compile(r"^(PASS|FAIL|ERROR) ")
FOOTER = re.compile(r"^(\d+) of (\d+) scenarios? passed \((\d+\.\d+) s since")


def script(variant: str) -> str:
    """The student's one file, with `variant` written in."""
    return STUDENT.read_text().replace(VARIANT_LINE, f'    variant = "{variant}"')


class Watch:
    """The watch command, its stdout lines in a queue (read by a thread)."""

    def __init__(self, folder: Path) -> None:
        self.popen = subprocess.Popen(
            [sys.executable, "-m", "harness.cli", "run", "--watch"]
            + ["--node", f"{sys.executable} node.py"],
            cwd=folder,
            env={**os.environ, "FOSSBOT_HIL_CACHE_DIR": str(folder / "cache")},
            stdout=subprocess.PIPE,
            text=True,
        )
        self.lines: queue.Queue[tuple[float, str]] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            self.lines.put((time.monotonic(), line.rstrip("\n")))

    def until(self, pattern: re.Pattern[str]) -> list[tuple[float, str]]:
        """Lines (with the time each was read) up to one matching `pattern`."""
        got = []
        deadline = time.monotonic() + LINE_TIMEOUT
        while True:
            try:
                at, line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                sys.exit(f"no line matching {pattern.pattern!r} in {LINE_TIMEOUT} s")
            got.append((at, line))
            if pattern.search(line):
                return got

    def stop(self) -> int:
        self.popen.send_signal(signal.SIGINT)
        return self.popen.wait(timeout=30)


def sample(watch: Watch, node: Path, variant: str) -> tuple[float, float, float]:
    """Save the fix; (save -> first verdict, save -> all passed, the watch's own seconds)."""
    node.write_text(script("correct"))
    saved = time.monotonic()
    lines = watch.until(FOOTER)
    first = next(at for at, line in lines if VERDICT.match(line))
    at, footer = lines[-1]
    match = FOOTER.match(footer)
    assert match and match[1] == match[2], f"not all passed: {footer}"
    node.write_text(script(variant))  # the bug again, for the next sample
    watch.until(FOOTER)
    return first - saved, at - saved, float(match[3])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=3)
    parser.add_argument("--variant", default="angle_in_degrees", help="the bug to fix")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="watch-latency-") as tmp:
        folder = Path(tmp)
        node = folder / "node.py"
        node.write_text(script(args.variant))
        watch = Watch(folder)
        try:
            first_run = watch.until(FOOTER)
            print(f"first run: {first_run[-1][1]}")
            samples = []
            for index in range(args.samples):
                verdict_s, passed_s, own_s = sample(watch, node, args.variant)
                samples.append((verdict_s, passed_s, own_s))
                print(
                    f"sample {index + 1}: first verdict {verdict_s:.2f} s, "
                    f"7 of 7 passed {passed_s:.2f} s after the save "
                    f"(the watch: {own_s:.2f} s since it saw the change)"
                )
        finally:
            code = watch.stop()
    medians = [statistics.median(column) for column in zip(*samples, strict=True)]
    print(
        f"median of {len(samples)}: first verdict {medians[0]:.2f} s, "
        f"all passed {medians[1]:.2f} s after the save (the watch: {medians[2]:.2f} s); "
        f"load average {os.getloadavg()[0]:.2f}; exit code on Ctrl-C {code}"
    )


if __name__ == "__main__":
    main()
