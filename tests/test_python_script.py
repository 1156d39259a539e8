"""Which node commands run a Python script the warm fork server may serve (no processes)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from harness.nodes.python_script import (
    ScriptCommand,
    environment_difference,
    script_command,
)

ENV = {"PATH": os.path.dirname(sys.executable) + ":/usr/bin:/bin"}


def test_python_and_a_script(tmp_path: Path) -> None:
    script = tmp_path / "node.py"
    script.write_text("")
    found = script_command(["python3", "-u", str(script), "a", "--ros-args"], ENV)
    assert isinstance(found, ScriptCommand)
    assert found.script == str(script) and found.args == ("a", "--ros-args")
    assert os.path.dirname(found.interpreter) == os.path.dirname(sys.executable)


def test_a_console_script_runs_through_its_shebang(tmp_path: Path) -> None:
    program = tmp_path / "fossbot_lidar_node"
    program.write_text(f"#!{sys.executable}\n# EASY-INSTALL-ENTRY-SCRIPT\n")
    found = script_command([str(program), "--ros-args"], ENV)
    assert found == ScriptCommand(sys.executable, str(program), ("--ros-args",))
    env_program = tmp_path / "node"
    env_program.write_text("#!/usr/bin/env python3 -u\n")
    found = script_command([str(env_program)], ENV)
    assert isinstance(found, ScriptCommand) and found.script == str(env_program)


def test_what_is_not_a_served_script(tmp_path: Path) -> None:
    shell = tmp_path / "run.sh"
    shell.write_text("#!/bin/sh\nexec true\n")
    binary = tmp_path / "node_bin"
    binary.write_bytes(b"\x7fELF\x02\x01")
    assert script_command([str(shell)], ENV) == "not a Python script (its #! runs /bin/sh)"
    assert "compiled program" in str(script_command([str(binary)], ENV))
    assert script_command(["python3", "-m", "pkg.node"], ENV) == (
        "Python option -m (a fresh interpreter honours it)"
    )
    assert script_command(["python3", "-u"], ENV) == "no script to run"
    assert script_command(["no-such-program-here"], ENV) == "no-such-program-here not found"


def test_environment_read_as_an_interpreter_starts(tmp_path: Path) -> None:
    server = {"PATH": "/bin", "PYTHONPATH": "/a", "PYTHONUNBUFFERED": "1"}
    assert environment_difference({**server, "PYTHONPATH": "/b:/a"}, server) is None
    optimised = {**server, "PYTHONOPTIMIZE": "1"}
    assert "PYTHONOPTIMIZE" in str(environment_difference(optimised, server))
    assert "LD_PRELOAD" in str(environment_difference({**server, "LD_PRELOAD": "x.so"}, server))
    libraries = tmp_path / "lib"
    libraries.mkdir()
    assert environment_difference({**server, "LD_LIBRARY_PATH": str(libraries)}, server) is None
    (libraries / "libmsgs.so").write_text("")
    assert "shared libraries" in str(
        environment_difference({**server, "LD_LIBRARY_PATH": str(libraries)}, server)
    )
