"""Holder locks: the record naming who holds a lock, and how the lock is taken and let go."""

from __future__ import annotations

import os
import select
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.holder_lock import Held, Holder, held_here, take
from harness.report.folder_lock import LOCK_NAME, lock_folder

pytestmark = pytest.mark.timeout(30)

HOLDER = """
import sys
from pathlib import Path
from harness.holder_lock import take
lock = take(Path(sys.argv[1]), remove=sys.argv[2] == "remove")
print("held", flush=True)
sys.stdin.readline()  # hold until told
"""


class OtherProcess:
    """Another process holding a lock file until its stdin closes."""

    def __init__(self, path: Path, *, remove: bool = False) -> None:
        self.popen = subprocess.Popen(
            [sys.executable, "-c", HOLDER, str(path), "remove" if remove else "keep"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.popen.stdout is not None
        assert select.select([self.popen.stdout], [], [], 20)[0], "the holder never took it"
        assert self.popen.stdout.readline() == "held\n"

    def let_go(self) -> None:
        assert self.popen.stdin is not None
        self.popen.stdin.close()
        self.popen.wait(timeout=10)


@pytest.fixture
def others() -> Iterator[list[OtherProcess]]:
    started: list[OtherProcess] = []
    yield started
    for other in started:
        if other.popen.poll() is None:
            other.popen.kill()
            other.popen.wait(timeout=10)


def test_the_record_names_pid_command_and_how_long() -> None:
    """What a holder writes is what a refused run reads back, one line of text."""
    record = Holder.record("fossbot-hil run --domain-id 42\nsecond line")
    holder = Holder.parse(record.decode())
    assert holder.pid == os.getpid()
    assert holder.command == "fossbot-hil run --domain-id 42 second line"
    assert holder.since is not None and abs(holder.since - time.time()) < 5
    assert str(holder) == f"pid {os.getpid()} (fossbot-hil run --domain-id 42 second line), for 0 s"
    long = Holder.parse(Holder.record("x" * 1000).decode())
    assert long.command == "x" * 157 + "..."


@pytest.mark.parametrize("text", ["", "\n", "not a pid\n1.0\ncmd\n", "123"])
def test_a_missing_or_garbled_record_is_another_run(text: str) -> None:
    """Locked but not written yet (or written by something else): no made-up pid."""
    assert str(Holder.parse(text)) == "another run"


def test_a_record_without_time_or_command_still_names_the_pid() -> None:
    assert str(Holder.parse("123\nlater\n")) == "pid 123"


def test_the_holder_overwrites_a_longer_stale_record(tmp_path: Path) -> None:
    """Lock files are reused: the last holder's longer record must leave no tail behind."""
    path = tmp_path / "7.lock"
    path.write_text("99999\n1.0\n" + "an old and much longer command line " * 3 + "\n")
    with take(path, command="short"):
        lines = path.read_text().split("\n")
    assert lines[0] == str(os.getpid()) and lines[2:] == ["short", ""]


def test_another_process_is_refused_and_told_who_holds_it(tmp_path: Path, others) -> None:
    path = tmp_path / "x.lock"
    other = OtherProcess(path)
    others.append(other)
    with pytest.raises(Held) as refused:
        take(path)
    assert refused.value.holder.pid == other.popen.pid
    assert refused.value.holder.command.startswith("-c ")
    other.let_go()
    with take(path):  # the kernel freed it with its holder
        pass


def test_a_bounded_wait_gets_the_lock_once_its_holder_lets_go(tmp_path: Path, others) -> None:
    path = tmp_path / "x.lock"
    other = OtherProcess(path)
    others.append(other)
    started = time.monotonic()
    with pytest.raises(Held):
        take(path, wait=0.2)
    assert time.monotonic() - started >= 0.2
    other.let_go()
    take(path, wait=5.0).release()


def test_within_a_process_a_lock_is_taken_once_unless_reentrant(tmp_path: Path) -> None:
    path = tmp_path / "x.lock"
    outer = take(path, reentrant=True)
    with pytest.raises(Held) as refused:
        take(path)
    assert refused.value.holder.pid == os.getpid()
    inner = take(path, reentrant=True)
    inner.release()
    assert held_here(path)
    outer.release()
    outer.release()  # twice is harmless
    assert not held_here(path)


def test_a_removable_lock_file_goes_with_its_last_holder(tmp_path: Path, others) -> None:
    """A report folder's lock leaves nothing behind; a killed holder's file is taken over."""
    path = tmp_path / LOCK_NAME
    with take(path, remove=True):
        assert path.exists()
    assert not path.exists()
    other = OtherProcess(path, remove=True)
    others.append(other)
    other.popen.kill()
    other.popen.wait(timeout=10)
    assert path.exists()  # killed: it could not remove it
    with take(path, remove=True):
        assert Holder.parse(path.read_text()).pid == os.getpid()
    assert not path.exists()


def test_a_folder_held_by_another_run_is_a_config_error_naming_it(tmp_path: Path, others) -> None:
    other = OtherProcess(tmp_path / LOCK_NAME, remove=True)
    others.append(other)
    with pytest.raises(ConfigError) as refused:
        lock_folder(tmp_path, "--out report")
    message = str(refused.value)
    assert message.startswith(f"--out report: in use by pid {other.popen.pid} (-c ")
    assert "two runs writing one folder would mix their reports" in message
    assert "\n" not in message
