"""Bounded children: a student's build or run that hangs, floods or forks is stopped, all of it."""

from __future__ import annotations

import errno
import sys
import threading
from pathlib import Path

import pytest
from child_process import alive

from harness.grading.process import run_bounded

pytestmark = pytest.mark.timeout(60)


def test_exit_code_and_output_go_to_the_log(tmp_path: Path) -> None:
    """A child that finishes: its code, and stdout and stderr together in the log."""
    log = tmp_path / "child.log"
    code = "import sys; print('out'); print('err', file=sys.stderr); sys.exit(3)"
    done = run_bounded([sys.executable, "-c", code], log=log, timeout=30, max_log_bytes=10_000)
    assert (done.returncode, done.timed_out, done.ok) == (3, False, False)
    assert log.read_text().split() == ["out", "err"]


def test_a_hang_is_stopped_with_everything_it_started(tmp_path: Path) -> None:
    """At the time limit the whole process group goes, the grandchild included."""
    pid_file = tmp_path / "grandchild.pid"
    code = (
        "import subprocess, sys, time\n"
        "p = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(600)'])\n"
        f"open({str(pid_file)!r}, 'w').write(str(p.pid))\n"
        "time.sleep(600)\n"
    )
    done = run_bounded(
        [sys.executable, "-c", code], log=tmp_path / "log", timeout=2.0, max_log_bytes=10_000
    )
    assert done.timed_out and not done.ok
    assert done.wall_s < 20
    assert not alive(int(pid_file.read_text()))


def test_endless_output_is_stopped_at_the_log_limit(tmp_path: Path) -> None:
    """A child printing forever is stopped soon after the log passes its limit."""
    log = tmp_path / "log"
    code = "while True: print('x' * 1000)"
    done = run_bounded([sys.executable, "-c", code], log=log, timeout=30, max_log_bytes=200_000)
    assert done.flooded and not done.timed_out
    assert log.stat().st_size < 50_000_000


def test_no_file_a_child_writes_can_outgrow_the_cap(tmp_path: Path) -> None:
    """A node printing forever into a file of its own gets EFBIG at the cap, not the disk."""
    code = (
        "import sys\n"
        f"with open({str(tmp_path / 'big')!r}, 'wb') as f:\n"
        "    try:\n"
        "        f.write(b'x' * 3_000_000)\n"
        "    except OSError as err:\n"
        "        sys.exit(err.errno)\n"
    )
    done = run_bounded(
        [sys.executable, "-c", code],
        log=tmp_path / "log",
        timeout=30,
        max_log_bytes=10_000,
        max_file_bytes=1_000_000,
    )
    assert done.returncode == errno.EFBIG
    assert (tmp_path / "big").stat().st_size <= 1_000_000


def test_cancel_stops_a_running_child(tmp_path: Path) -> None:
    """Ctrl-C in the grader sets the flag; the child is stopped within a poll."""
    cancel = threading.Event()
    cancel.set()
    code = "import time; time.sleep(600)"
    done = run_bounded(
        [sys.executable, "-c", code],
        log=tmp_path / "log",
        timeout=30,
        max_log_bytes=10_000,
        cancel=cancel,
    )
    assert done.cancelled and done.wall_s < 20


def test_a_missing_program_is_reported_not_raised(tmp_path: Path) -> None:
    """The exec shim reports a program that does not exist and exits 127."""
    log = tmp_path / "log"
    done = run_bounded(["no-such-program-xyz"], log=log, timeout=30, max_log_bytes=10_000)
    assert done.returncode == 127
    assert "cannot run no-such-program-xyz" in log.read_text()
