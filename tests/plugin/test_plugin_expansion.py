"""`~` and `$VAR` in the plugin's node, workspace and port, from the command line and the ini
file (which no shell reads), expanded as the CLI expands them; an unset variable stops the
session with one line. Runs pytest inside pytest; nothing here starts ROS."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(60)

STUDENT = Path(__file__).parents[1] / "ros" / "student_node.py"


@pytest.fixture
def home(pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A home folder holding lab07/node.py and a workspace, as $HOME; $LAB is lab07."""
    home = pytester.path / "home"
    (home / "lab07").mkdir(parents=True)
    shutil.copy(STUDENT, home / "lab07" / "node.py")
    (home / "ws" / "install").mkdir(parents=True)
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.setenv("LAB", str(home / "lab07"))
    return home


def test_the_command_line_options_are_expanded(pytester: pytest.Pytester, home: Path) -> None:
    """--hil-node "python3 ~/lab07/node.py correct" runs the script in $HOME."""
    pytester.makepyfile(
        f"""
        def test_node(hil_node, hil_link_options):
            assert hil_node.command == "{sys.executable} {home}/lab07/node.py correct"
            assert hil_link_options.node == hil_node.command
        """
    )
    result = pytester.runpytest("--hil-node", f"{sys.executable} ~/lab07/node.py correct")
    result.assert_outcomes(passed=1)


def test_the_ini_files_values_are_expanded(pytester: pytest.Pytester, home: Path) -> None:
    """hil_node with $LAB and hil_workspace under ~: the ini file's values, expanded."""
    pytester.makeini(
        f"""
        [pytest]
        hil_node = {sys.executable} "$LAB/node.py" correct
        hil_workspace = ~/ws
        """
    )
    pytester.makepyfile(
        f"""
        def test_node(hil_node, hil_config):
            assert hil_node.command == "{sys.executable} {home}/lab07/node.py correct"
            assert hil_config.workspace == "{home}/ws"
        """
    )
    pytester.runpytest().assert_outcomes(passed=1)


@pytest.mark.parametrize(
    ("ini", "args", "message"),
    [
        (
            "hil_node = python3 $NOPE/node.py",
            [],
            "hil_node in tox.ini 'python3 $NOPE/node.py': $NOPE is not set: set it (export "
            "NOPE=...), or write the value out",
        ),
        ("", ["--hil-workspace", "${NOPE}/ws"], "--hil-workspace '${NOPE}/ws': $NOPE is not set"),
        ("", ["--hil-node", "python3 $(pwd)/n.py"], "--hil-node 'python3 $(pwd)/n.py': $(...)"),
        ("", ["--hil-port", "$NOPE"], "--hil-port '$NOPE': $NOPE is not set"),
    ],
)
def test_an_unset_variable_is_one_usage_line(
    pytester: pytest.Pytester,
    monkeypatch: pytest.MonkeyPatch,
    ini: str,
    args: list[str],
    message: str,
) -> None:
    monkeypatch.delenv("NOPE", raising=False)
    if ini:
        pytester.makeini(f"[pytest]\n{ini}\n")
    pytester.makepyfile("def test_never_runs(): raise AssertionError")
    result = pytester.runpytest(*args)
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    lines = [line for line in result.stderr.lines if message in line]
    assert len(lines) == 1, result.stderr.str()
    assert "Traceback" not in result.stderr.str()
