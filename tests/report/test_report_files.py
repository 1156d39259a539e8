"""Report files: modes follow the umask, and a writer killed mid-write leaves nothing for long."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from harness.atomic_write import write_atomically
from harness.judge.records import RunResult
from harness.report.junit import write_junit
from harness.report.outputs import write_report


def modes(folder: Path) -> dict[str, int]:
    """Every file below `folder` (hidden ones too) -> its permission bits."""
    return {
        str(p.relative_to(folder)): stat.S_IMODE(p.stat().st_mode)
        for p in folder.rglob("*")
        if p.is_file()
    }


@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o002, 0o664)], ids=["022", "002"])
def test_report_files_follow_the_umask(
    tmp_path: Path, passing: RunResult, umask: int, mode: int
) -> None:
    """--out and --junit-xml files get 0666 less the umask, like any other tool's files."""
    old = os.umask(umask)
    try:
        write_report(tmp_path / "report", [passing])
        write_junit(tmp_path / "ci.xml", [passing])
    finally:
        os.umask(old)
    found = modes(tmp_path)
    assert set(found) == {
        "ci.xml",
        "report/index.html",
        "report/junit.xml",
        "report/summary.json",
        "report/scenarios/approach_wall.json",
        "report/scenarios/approach_wall.mcap",
        "report/scenarios/approach_wall.png",
    }  # and no temporary file left
    assert set(found.values()) == {mode}, found


def _exited_pid() -> int:
    """The pid of a process that has come and gone."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_stale_temporary_files_are_removed_by_the_next_write(tmp_path: Path) -> None:
    """Only temporaries whose writer is gone go: not ours, not a live one's, nothing else."""
    dead = _exited_pid()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        stale = tmp_path / f".summary.json.hil-{dead}-0123abcd.tmp"
        stale_png = tmp_path / f".wall.png.hil-{dead}-89abcdef.tmp.png"
        kept = [
            tmp_path / f".index.html.hil-{os.getpid()}-0123abcd.tmp",  # ours: in use
            tmp_path / f".index.html.hil-{live.pid}-0123abcd.tmp",  # a running writer's
            tmp_path / f".notes.{dead}.tmp",  # not one of ours
            tmp_path / "summary.json",
        ]
        for path in [stale, stale_png, *kept]:
            path.write_bytes(b"")
        write_atomically(tmp_path / "junit.xml", b"<testsuites/>")
        left = sorted(p.name for p in tmp_path.iterdir())
        assert left == sorted([*(p.name for p in kept), "junit.xml"])
    finally:
        live.kill()
        live.wait()


WRITER = """
import os, sys, time
from harness.atomic_write import write_atomically

def stuck(handle):  # the data is written; the writer is killed before it is renamed
    print("writing", flush=True)
    time.sleep(60)

os.fsync = stuck
write_atomically(sys.argv[1], b"x" * 1_000_000)
"""


@pytest.mark.timeout(60)
def test_a_writer_killed_mid_write_leaves_a_temporary_the_next_write_removes(
    tmp_path: Path,
) -> None:
    """SIGKILL during write_atomically: the final name is untouched, the temporary names
    the dead writer's pid, and the next write into the folder removes it."""
    target = tmp_path / "summary.json"
    target.write_text("{}")
    child = subprocess.Popen(
        [sys.executable, "-c", WRITER, str(target)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert child.stdout is not None and child.stdout.readline() == "writing\n"
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
        child.stdout.close()  # type: ignore[union-attr]
    [temporary] = [p for p in tmp_path.iterdir() if p.name != target.name]
    assert temporary.name.startswith(f".summary.json.hil-{child.pid}-")
    assert target.read_text() == "{}"
    write_atomically(tmp_path / "index.html", b"<html>")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["index.html", "summary.json"]
