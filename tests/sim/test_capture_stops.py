"""A Ctrl-C that lands while PyBullet's chatter is captured must not leave fds 1 and 2
pointed at the capture: what the run prints after the stop (emulate's summary, the
CLI's "interrupted by SIGINT") would go into a deleted file, and the user see nothing."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# Captures over and over while another thread sends SIGINT every few hundred µs;
# prints how many captures ran, how many a stop ended, and whether fds 1 and 2 moved.
HAMMER = textwrap.dedent(
    """
    import os, random, signal, sys, threading, time
    from harness.sim import bullet

    where = (os.fstat(1).st_ino, os.fstat(2).st_ino)
    main, done = threading.get_ident(), threading.Event()

    def shoot():
        rnd = random.Random(7)
        while not done.is_set():
            time.sleep(rnd.uniform(0, 0.0003))
            signal.pthread_kill(main, signal.SIGINT)

    signal.signal(signal.SIGINT, signal.default_int_handler)
    threading.Thread(target=shoot, daemon=True).start()
    runs = stopped = 0
    moved = False
    deadline = time.monotonic() + 1.5
    while not moved:
        try:
            if time.monotonic() > deadline:
                break
            runs += 1
            with bullet.captured_output():
                pass
        except KeyboardInterrupt:
            stopped += 1
        try:
            moved = (os.fstat(1).st_ino, os.fstat(2).st_ino) != where
        except KeyboardInterrupt:
            pass
    while True:  # ignored first: the stops still on their way; one may land in here
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            break
        except KeyboardInterrupt:
            pass
    done.set()
    with open(sys.argv[1], "w") as out:
        out.write(f"{runs} {stopped} {moved}")
    """
)


def test_a_stop_at_any_moment_of_a_capture_leaves_stdout_and_stderr_where_they_were(
    tmp_path: Path,
) -> None:
    report = tmp_path / "report"
    ran = subprocess.run(
        [sys.executable, "-c", HAMMER, str(report)], cwd=ROOT, timeout=60, capture_output=True
    )
    assert report.exists(), f"exit {ran.returncode}, no report:\n{ran.stderr.decode()[-2000:]}"
    runs, stopped, moved = report.read_text().split()
    assert moved == "False", f"fds 1 and 2 left on the capture after {runs} captures"
    assert int(stopped) > 10, f"only {stopped} of {runs} captures met a stop: the test saw none"
