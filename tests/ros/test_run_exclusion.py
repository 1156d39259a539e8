"""Two runs at once on one --domain-id or one --out: the second is refused, the first unharmed.

Real `fossbot-hil` processes. The first run's node (tests/ros/gated_node.py)
starts only when the test opens its gate, so the first run holds its domain
and report folder for as long as the test needs; the test waits (bounded)
until the first run's pid is in the lock file, starts the second, and then
lets the first finish.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from command_line import COMMAND, fossbot_hil

from harness.holder_lock import Held, Holder, take
from harness.report.folder_lock import LOCK_NAME
from harness.ros.domain import FIRST_ID, LAST_ID, lock_file

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

GATED = Path(__file__).parent / "gated_node.py"


class HeldRun:
    """`fossbot-hil run approach_wall ...` whose node starts once `open_gate()` is called."""

    def __init__(self, tmp_path: Path, *extra: str) -> None:
        self.gate = tmp_path / "gate"
        self.popen = subprocess.Popen(
            [
                *COMMAND,
                "run",
                "approach_wall",
                "--node",
                f"{sys.executable} {GATED} {self.gate}",
                "--ready-timeout",
                "60",
                *extra,
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )

    def wait_holding(self, lock: Path, timeout: float = 30.0) -> None:
        """Until this run's pid is in `lock` (written only by a holder, after locking)."""
        deadline = time.monotonic() + timeout
        while not (lock.exists() and Holder.parse(lock.read_text()).pid == self.popen.pid):
            if self.popen.poll() is not None:
                out, err = self.popen.communicate()
                pytest.fail(f"the first run ended before it held {lock}:\n{out}{err}")
            assert time.monotonic() < deadline, f"the first run never held {lock}"
            time.sleep(0.02)  # polling a bounded condition

    def finish(self) -> tuple[int, str]:
        self.gate.touch()
        out, err = self.popen.communicate(timeout=90)
        return self.popen.returncode, out + err

    def kill(self) -> None:
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.communicate(timeout=30)


@pytest.fixture
def held_runs(tmp_path: Path):
    runs: list[HeldRun] = []

    def start(*extra: str) -> HeldRun:
        runs.append(HeldRun(tmp_path, *extra))
        return runs[-1]

    yield start
    for run in runs:
        run.kill()


def free_domain() -> int:
    """An id no run holds now (not held by this process afterwards, so nothing joins it)."""
    for candidate in range(LAST_ID, FIRST_ID - 1, -1):
        try:
            take(lock_file(candidate)).release()
        except (Held, OSError):
            continue
        return candidate
    pytest.fail("no free domain id")


def one_error_line(done: subprocess.CompletedProcess[str]) -> str:
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1, done.stdout + done.stderr
    return lines[0]


def test_a_second_run_on_the_same_domain_id_exits_2_naming_the_first(held_runs) -> None:
    domain_id = free_domain()
    first = held_runs("--domain-id", str(domain_id))
    first.wait_holding(lock_file(domain_id))
    second = fossbot_hil("run", "approach_wall", "--domain-id", str(domain_id), timeout=60)
    line = one_error_line(second)
    holder = f"pid {first.popen.pid} (fossbot-hil run approach_wall --node "
    assert f"ROS domain {domain_id} is in use by {holder}" in line, line
    code, output = first.finish()
    assert code == 0 and "1 of 1 scenario passed" in output, output


def test_a_second_run_into_the_same_out_folder_exits_2_and_leaves_it_alone(
    held_runs, tmp_path: Path
) -> None:
    out = tmp_path / "report"
    first = held_runs("--out", str(out))
    first.wait_holding(out / LOCK_NAME)
    second = fossbot_hil("run", "drive_past_10m", "--out", str(out), timeout=60)
    line = one_error_line(second)
    assert f"--out {out}: in use by pid {first.popen.pid} (fossbot-hil run " in line, line
    code, output = first.finish()
    assert code == 0, output
    summary = json.loads((out / "summary.json").read_text())
    assert [s["scenario"] for s in summary["scenarios"]] == ["approach_wall"]
    junit = (out / "junit.xml").read_text()
    assert "approach_wall" in junit and "drive_past_10m" not in junit
    assert sorted(p.name for p in (out / "scenarios").iterdir()) == [
        "approach_wall.json",
        "approach_wall.mcap",
        "approach_wall.png",
    ]
    assert not (out / LOCK_NAME).exists()  # let go at the end, and removed


HOLD_FOLDER = """
import sys
from pathlib import Path
from harness.report.folder_lock import lock_folder
lock = lock_folder(Path(sys.argv[1]), "holder")
print("held", flush=True)
sys.stdin.readline()
"""


def test_grade_into_a_folder_another_grade_writes_exits_2(tmp_path: Path) -> None:
    """`grade --out` takes the same lock before it clears last time's students."""
    student = tmp_path / "class" / "alex"
    student.mkdir(parents=True)
    (student / "node.py").write_text("import rclpy\n")
    out = tmp_path / "grades"
    out.mkdir()
    (out / ".fossbot-hil-grades").write_text("written by fossbot-hil grade\n")
    (out / "students").mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD_FOLDER, str(out)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        done = fossbot_hil("grade", str(tmp_path / "class"), "--out", str(out), timeout=60)
        line = one_error_line(done)
        assert f"--out {out}: in use by pid {holder.pid} (-c " in line, line
        assert (out / "students").is_dir()  # last time's students: not cleared
    finally:
        holder.kill()
        holder.wait(timeout=10)
