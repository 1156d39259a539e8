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
    main, go, done = threading.get_ident(), threading.Event(), threading.Event()

    def shoot():
        go.wait()
        rnd = random.Random(7)
        while not done.is_set():
            time.sleep(rnd.uniform(0, 0.0003))
            signal.pthread_kill(main, signal.SIGINT)

    signal.signal(signal.SIGINT, signal.default_int_handler)
    threading.Thread(target=shoot, daemon=True).start()
    count = {"runs": 0, "stopped": 0, "moved": False}
    deadline = time.monotonic() + 1.5
    while True:  # a stop may land anywhere in here, not only in the capture: go on
        try:
            go.set()
            while not count["moved"] and time.monotonic() < deadline:
                count["runs"] += 1
                try:
                    with bullet.captured_output():
                        pass
                except KeyboardInterrupt:
                    count["stopped"] += 1
                count["moved"] = (os.fstat(1).st_ino, os.fstat(2).st_ino) != where
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # the stops still on their way
            break
        except KeyboardInterrupt:
            pass
    done.set()
    with open(sys.argv[1], "w") as out:
        out.write(f"{count['runs']} {count['stopped']} {count['moved']}")
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
