"""Students' Python nodes started by fork from the warm Python: the same node a fresh
interpreter would run, its code read afresh every time, and what cannot be served so
started as the command it is."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from child_process import alive

from harness.nodes.command import NodeCommand, shell_node
from harness.nodes.forkserver import ForkedSupervisor
from harness.nodes.process import NodeProcess
from harness.nodes.python_script import FORKED

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

STUDENT_NODE = Path(__file__).with_name("student_node.py")

# A node that says on stderr what it was given and where it runs, then waits to be stopped.
TELLING_NODE = textwrap.dedent(
    """
    import os, sys, time
    import rclpy
    MARK = "first"
    print("mark", MARK, "argv", sys.argv[1:], "cwd", os.getcwd(), file=sys.stderr)
    print("path0", sys.path[0], "file", __file__, "name", __name__, file=sys.stderr)
    print("profile", os.environ.get("FASTRTPS_DEFAULT_PROFILES_FILE"), file=sys.stderr)
    try:
        while True:
            time.sleep(0.05)
    except KeyboardInterrupt:
        pass
    """
)


CRASHING = "import rclpy\n\n\ndef main():\n    raise ValueError('no scan yet')\n\n\nmain()\n"


def wait_for(process: NodeProcess, text: str, seconds: float = 10.0) -> str:
    """The node's stderr once a whole line of it holds `text` (bounded): a command's
    stderr is unbuffered, so a print's words may be read before the rest of its line."""
    import time

    def said() -> bool:
        output = process._outputs.get("stderr")
        lines = output.text().splitlines(keepends=True) if output is not None else []
        return any(text in line and line.endswith("\n") for line in lines)

    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if said():
            return process.tail("stderr", 40)
        if process.returncode() is not None:
            break
        time.sleep(0.02)
    return process.tail("stderr", 40)


def started(command: NodeCommand, env: dict[str, str] | None = None) -> NodeProcess:
    process = NodeProcess(command, ["--ros-args", "-p", "x:=1"], env or {})
    process.start()
    return process


def test_a_script_is_forked_and_read_afresh_every_time(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from harness.ros.domain import reserve_domain
    from harness.ros.observer import Observer  # the harness's participant, before the node

    domain = reserve_domain(None)
    try:
        Observer(domain.domain_id, scan_topic="/s", status_topic="/t", warning_topic="/w").close()
    finally:
        domain.release()
    script = tmp_path / "node.py"
    script.write_text(TELLING_NODE)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    command = shell_node(f"python3 {script} extra")
    process = started(command)
    try:
        assert isinstance(process._popen, ForkedSupervisor), process.how
        assert process.how == FORKED
        said = wait_for(process, "path0")
        # What a fresh `python3 node.py extra --ros-args ...` would have.
        assert "mark first argv ['extra', '--ros-args', '-p', 'x:=1']" in said
        assert f"cwd {work}" in said
        assert f"path0 {tmp_path} file {script} name __main__" in said
        assert "profile None" in said  # the harness's own DDS profile is not the node's
        assert process.stop() == 0
    finally:
        process.stop()
    script.write_text(TELLING_NODE.replace('MARK = "first"', 'MARK = "second"'))
    again = started(command)
    try:
        assert "mark second" in wait_for(again, "mark"), again.tail()
    finally:
        again.stop()
        assert again.node_pid is not None and not alive(again.node_pid)


def test_a_python_shebang_script_is_forked(tmp_path: Path) -> None:
    script = tmp_path / "node"
    script.write_text(f"#!/usr/bin/env python3\n{TELLING_NODE}")
    script.chmod(0o755)
    process = started(shell_node(str(script)))
    try:
        assert process.how == FORKED
        assert "argv ['--ros-args'" in wait_for(process, "argv")
    finally:
        process.stop()


def test_an_uncaught_error_reads_as_from_a_fresh_interpreter(tmp_path: Path) -> None:
    script = tmp_path / "crashing.py"
    script.write_text(CRASHING)
    process = started(shell_node(f"python3 {script}"))
    try:
        said = wait_for(process, "ValueError")
        assert process.how == FORKED
        assert said.splitlines()[0] == "Traceback (most recent call last):"
        assert f'File "{script}", line 8, in <module>' in said.splitlines()[1]
        assert "runpy" not in said and "forkserver" not in said
        assert said.rstrip().endswith("ValueError: no scan yet")
    finally:
        assert process.stop() == 1


@pytest.mark.parametrize(
    ("how", "reason"),
    [
        ("wrapper", "not a Python script (its #! runs /bin/sh)"),
        ("optimised", "Python option -O"),
        ("shadowed", "would import numpy from elsewhere"),
        ("warnings", "PYTHONWARNINGS differs"),
    ],
)
def test_what_a_fork_would_change_starts_as_a_command(
    tmp_path: Path, how: str, reason: str
) -> None:
    script = tmp_path / "node.py"
    script.write_text(TELLING_NODE)
    env: dict[str, str] = {}
    command = f"python3 {script}"
    if how == "wrapper":
        wrapper = tmp_path / "run.sh"
        wrapper.write_text(f'#!/bin/sh\nexec {sys.executable} {script} "$@"\n')
        wrapper.chmod(0o755)
        command = str(wrapper)
    elif how == "optimised":
        command = f"python3 -O {script}"
    elif how == "shadowed":  # a module beside the script that a fresh Python would import
        (tmp_path / "numpy.py").write_text("")
    elif how == "warnings":
        env = {"PYTHONWARNINGS": "error"}
    process = started(shell_node(command), env)
    try:
        assert isinstance(process._popen, subprocess.Popen)
        assert process.how.startswith("started as a command: ") and reason in process.how
        assert "mark first" in wait_for(process, "mark")
    finally:
        process.stop()


def test_another_python_starts_as_a_command(tmp_path: Path) -> None:
    other = shutil.which("python3", path="/usr/bin")
    if other is None or os.path.realpath(other) == os.path.realpath(sys.executable):
        pytest.skip("no other Python here")
    script = tmp_path / "node.py"
    script.write_text("print('hello')\n")
    process = started(NodeCommand((other, str(script))))
    try:
        assert isinstance(process._popen, subprocess.Popen)
        assert process.how.startswith("started as a command: ")
    finally:
        process.stop()


def test_a_student_suite_names_how_its_node_started(tmp_path: Path) -> None:
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "harness.cli",
            "run",
            "approach_wall",
            "--node",
            f"python3 {STUDENT_NODE} correct",
        ],
        capture_output=True,
        text=True,
        timeout=90,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    lines = [line for line in done.stdout.splitlines() if line.startswith("node: ")]
    assert lines == [f"node: python3 {STUDENT_NODE} correct, {FORKED}"]
