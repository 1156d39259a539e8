"""`run --watch --workspace W --package P --executable E`: a colcon workspace, edited.

A copy of node/fossbot_lidar_processing with a student's bug in it (the
angle without angle_min), built once with colcon as the student would. A
plain build installs copies, so each save is built (`colcon build
--packages-select`) before the run; a build that fails shows why and skips
the run until the next save. A --symlink-install build runs the sources
where they are: a .py save needs no build. Each colcon build takes seconds,
so these tests build as few times as they can.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from watch_process import save, verdict_lines

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(300)]

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "fossbot_lidar_processing"
RIGHT = "angle = float(angle_min) + index * float(angle_increment)"
WRONG = "angle = index * float(angle_increment)"  # angle_min left out
# approach_wall's scan starts at -pi (the bug shows); obstacle_at_side's at 0 (it does not)
SCENARIOS = ("obstacle_at_side", "approach_wall")
BUILD_TIMEOUT = 180


def workspace(root: Path, *, symlink_install: bool) -> Path:
    """The package copied into root/src with the bug, built once; its scan_logic.py."""
    source = root / "src" / PACKAGE
    shutil.copytree(
        REPO / "node" / PACKAGE, source, ignore=shutil.ignore_patterns(".*", "__pycache__", "test")
    )
    logic = source / PACKAGE / "scan_logic.py"
    text = logic.read_text()
    assert RIGHT in text
    save(logic, text.replace(RIGHT, WRONG))
    colcon = shutil.which("colcon")
    assert colcon is not None, "colcon is not installed: pip install '.[test]' installs it"
    command = [colcon, "build", *(["--symlink-install"] if symlink_install else [])]
    done = subprocess.run(
        command, cwd=root, capture_output=True, text=True, timeout=BUILD_TIMEOUT, check=False
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return logic


def node_options(root: Path) -> list[str]:
    return ["--workspace", str(root), "--package", PACKAGE, "--executable", "fossbot_lidar_node"]


def test_a_save_is_built_then_run_and_a_failed_build_waits(tmp_path: Path, start_watch) -> None:
    """Plain build: a save that breaks setup.py fails its build (why, and the log's tail, on
    screen; no run); the save that mends it builds and runs, the failed scenario first."""
    logic = workspace(tmp_path, symlink_install=False)
    setup = logic.parent.parent / "setup.py"
    good_setup = setup.read_text()
    watch = start_watch(*SCENARIOS, *node_options(tmp_path))
    watched = watch.expect("^Ctrl-C to stop")
    assert f"watching package {PACKAGE} in" in watched[0] and "rebuilt on change" in watched[0]
    first = watch.expect(r"scenarios? passed")
    assert first[-1].startswith("1 of 2 scenarios passed"), first
    watch.expect("watching for changes")

    save(setup, good_setup + "\ndef broken(:\n")  # broken first: every build fails
    save(logic, logic.read_text().replace(WRONG, RIGHT))  # the fix, in the same moment
    watch.expect(rf"^building {PACKAGE} with colcon \.\.\. \(log: .*fossbot-hil-watch\.log\)")
    failed = watch.expect(r"^build failed: ")
    assert "setup.py" in failed[-1] and "not run until the next save" in failed[-1], failed
    tail = watch.expect("watching for changes")
    assert any("SyntaxError" in line for line in tail), tail

    save(setup, good_setup)
    rest = watch.expect(r"scenarios? passed")
    built = [i for i, line in enumerate(rest) if line.startswith(f"built {PACKAGE} in ")]
    runs = [i for i, line in enumerate(rest) if line.startswith("run 2: changed ")]
    assert built and runs and built[-1] < runs[0], rest
    assert "failed last time first: approach_wall" in rest[runs[0]]
    assert verdict_lines(rest) == ["approach_wall", "obstacle_at_side"]
    assert rest[-1].startswith("2 of 2 scenarios passed"), rest
    assert watch.interrupt() == 130 and "Traceback" not in watch.stderr()


def test_a_symlink_install_runs_a_save_without_a_build(tmp_path: Path, start_watch) -> None:
    """--symlink-install: the saved .py is what the next node runs, with no colcon build."""
    logic = workspace(tmp_path, symlink_install=True)
    watch = start_watch(*SCENARIOS, *node_options(tmp_path))
    assert "a .py change needs no build" in watch.expect("^Ctrl-C to stop")[0]
    assert watch.expect(r"scenarios? passed")[-1].startswith("1 of 2 scenarios passed")
    watch.expect("watching for changes")
    save(logic, logic.read_text().replace(WRONG, RIGHT))
    rest = watch.expect(r"scenarios? passed")
    assert not any(line.startswith("building") for line in rest), rest
    assert rest[-1].startswith("2 of 2 scenarios passed"), rest
    assert watch.interrupt() == 130
