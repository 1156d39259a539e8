"""Running `fossbot-hil` on hostile input and checking it failed cleanly.

Clean means: exit code 2, exactly one line on stderr (``fossbot-hil:
error: ...``), no traceback, nothing on stdout, no process left running and
no file left behind. Two ways to run it:

- in this process (`run_in_process`): fast, for input that is refused
  before anything starts; a child process it left would be our child;
- as a real command (`run_command`): for input that could start a node, a
  board or PyBullet's crash-prone parsers. The command gets a marker in its
  environment, which every process it starts inherits, so leftovers are
  found in /proc even after they were re-parented; and its own TMPDIR, so
  temporary files it forgot are found too.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import uuid
from dataclasses import dataclass
from pathlib import Path

import pytest

from harness.cli import main

COMMAND = [sys.executable, "-m", "harness.cli"]
COMMAND_TIMEOUT_S = 60.0
#: Lock folders the harness keeps in the temp folder on purpose (one file per
#: port or domain id, reused by every later run): not leftovers.
LOCK_FOLDERS = {"fossbot-hil-ports", "fossbot-hil-domains"}


@dataclass(frozen=True)
class Outcome:
    """What one run of the command did."""

    code: int
    stdout: str
    stderr: str


def children_of(pid: int) -> set[int]:
    """Processes whose parent is `pid`, from /proc."""
    found = set()
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue  # gone meanwhile
        # pid (comm) state ppid ...; comm may hold spaces and parentheses
        fields = stat.rsplit(")", 1)[-1].split()
        if len(fields) > 1 and int(fields[1]) == pid:
            found.add(int(entry))
    return found


def marked_processes(marker: str) -> list[int]:
    """Processes (of any parent) whose environment carries `marker`."""
    needle = marker.encode()
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            environ = Path(f"/proc/{entry}/environ").read_bytes()
        except OSError:
            continue
        if needle in environ:
            found.append(int(entry))
    return found


def listing(folder: Path) -> set[str]:
    """Every path below `folder`, relative to it."""
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def run_in_process(
    args: list[str],
    workdir: Path,
    capfd: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> Outcome:
    """`fossbot-hil ARGS` through ``main`` in `workdir`, temp files in `workdir`/tmp."""
    tmp = workdir / "tmp"
    tmp.mkdir(exist_ok=True)
    monkeypatch.chdir(workdir)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    capfd.readouterr()
    before = children_of(os.getpid())
    code = main(args)
    captured = capfd.readouterr()
    left = children_of(os.getpid()) - before
    assert not left, f"child processes left running: {sorted(left)}"
    return Outcome(code, captured.out, captured.err)


def run_command(
    args: list[str],
    workdir: Path,
    *,
    timeout: float = COMMAND_TIMEOUT_S,
    env: dict[str, str] | None = None,
) -> Outcome:
    """The real `fossbot-hil ARGS` in `workdir` (with `env` added to the environment);
    fails if anything it started outlives it."""
    tmp = workdir / "tmp"
    tmp.mkdir(exist_ok=True)
    marker = f"FOSSBOT_HIL_HOSTILE_TEST={uuid.uuid4().hex}"
    name, _, value = marker.partition("=")
    env = {**os.environ, **(env or {}), name: value, "TMPDIR": str(tmp)}
    try:
        done = subprocess.run(
            [*COMMAND, *args],
            cwd=workdir,
            env=env,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired as err:
        pytest.fail(f"fossbot-hil {' '.join(args)[:200]} still running after {err.timeout} s")
    left = marked_processes(marker)
    assert not left, f"processes left running: {left}"
    return Outcome(done.returncode, done.stdout, done.stderr)


def assert_refused(outcome: Outcome, phrase: str) -> str:
    """Exit 2, one stderr line naming the problem (`phrase`), no traceback, no stdout."""
    assert "Traceback" not in outcome.stderr, outcome.stderr
    assert outcome.code == 2, (outcome.code, outcome.stdout[-2000:], outcome.stderr[-2000:])
    lines = outcome.stderr.splitlines()
    assert len(lines) == 1 and outcome.stderr.endswith("\n"), outcome.stderr[-2000:]
    assert lines[0].startswith("fossbot-hil: error: "), lines[0]
    assert lines[0].isprintable(), repr(lines[0])  # no escape sequences, no stray controls
    assert phrase in lines[0], (phrase, lines[0])
    assert outcome.stdout == "", outcome.stdout[-2000:]
    return lines[0]


def assert_nothing_left(workdir: Path, before: set[str]) -> None:
    """The working folder is as it was and the run's temp folder holds only lock folders."""
    tmp = workdir / "tmp"
    after = listing(workdir)
    kept = {p for p in after if p == "tmp" or p.startswith("tmp/")}
    assert after - kept == before - {"tmp"}, sorted((after - kept) ^ (before - {"tmp"}))
    if tmp.is_dir():
        stray = {p for p in listing(tmp) if p.split("/", 1)[0] not in LOCK_FOLDERS}
        assert not stray, sorted(stray)
