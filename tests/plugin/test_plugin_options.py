"""Plugin options: command line over ini over defaults, mirrored by fixtures; bad values are
one usage line. Runs pytest inside pytest (pytester); nothing here starts ROS."""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(60)

STUDENT = Path(__file__).parents[1] / "ros" / "student_node.py"


def test_options_and_ini_keys_are_listed_in_help(pytester: pytest.Pytester) -> None:
    """`pytest --help` shows the group, each option and its ini twin."""
    result = pytester.runpytest("--help")
    out = result.stdout.str()
    for flag in ("--hil-link", "--hil-node", "--hil-package", "--hil-executable"):
        assert flag in out
    for flag in ("--hil-workspace", "--hil-param", "--hil-port", "--hil-domain-id"):
        assert flag in out
    for flag in ("--hil-seed", "--hil-timeout", "--hil-ready-timeout", "--hil-port-wait"):
        assert flag in out
    assert "hil_node (string)" in out and "hil_param (linelist)" in out
    assert "hil_port (" not in out  # a port belongs to one machine, not to a project


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--hil-seed", "x"], "argument --hil-seed: seed must be a whole number, got 'x'"),
        (["--hil-warning-when-clear", "yes"], "give optional or required, got 'yes'"),
        (["--hil-domain-id", "999"], "domain id must be a whole number 0..232, got '999'"),
        (["--hil-timeout", "0"], "timeout must be a positive number, got '0'"),
        (["--hil-param", "threshold=0.3"], "expected NAME:=VALUE, got 'threshold=0.3'"),
        (["--hil-link", "serial"], "unknown link 'serial' (known: inprocess, ldlidar, r"),
        (["--hil-node", "x", "--hil-package", "p"], "--hil-node and --hil-package: give one"),
        (["--hil-package", "p"], "--hil-package and --hil-executable go together"),
        (["--hil-node", "./nope.py"], "--hil-node './nope.py': no such file ./nope.py"),
        (["--hil-node", "no-such-program"], "'no-such-program' not found on PATH"),
        (
            ["--hil-package", "p", "--hil-executable", "e", "--hil-workspace", "/nonexistent"],
            "--hil-workspace /nonexistent: no such folder",
        ),
        (["--hil-link", "inprocess", "--hil-param", "a:=1"], "--hil-param needs a link that"),
        (["--hil-port=/dev/null", "--hil-link", "ros2"], "--hil-port needs --hil-link rplidar or"),
        (["--hil-port=/nonexistent/ttyUSB9"], "--hil-port /nonexistent/ttyUSB9: no such device"),
        (["-n", "2", "--hil-domain-id", "3"], "--hil-domain-id 3 with 2 xdist workers"),
    ],
)
def test_bad_options_are_one_line_usage_errors(
    pytester: pytest.Pytester, args: list[str], message: str
) -> None:
    """Each mistake stops the session before any test, with one line that says what is wrong."""
    pytester.makepyfile("def test_never_runs(): raise AssertionError")
    result = pytester.runpytest(*args)
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    lines = [line for line in result.stderr.lines if message in line]
    assert len(lines) == 1, result.stderr.str()
    assert "Traceback" not in result.stderr.str()


def test_bad_ini_value_names_the_key_and_file(pytester: pytest.Pytester) -> None:
    pytester.makeini("[pytest]\nhil_seed = many\n")
    pytester.makepyfile("def test_never_runs(): raise AssertionError")
    result = pytester.runpytest()
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    result.stderr.fnmatch_lines(["*hil_seed in tox.ini: seed must be a whole number, got 'many'"])


def test_ini_gives_defaults_and_the_command_line_wins(pytester: pytest.Pytester) -> None:
    """A project fixes its node in the ini file; a user overrides a value for one session."""
    (pytester.path / "ws" / "install").mkdir(parents=True)
    pytester.makeini(
        f"""
        [pytest]
        hil_node = {sys.executable} {STUDENT} correct
        hil_param =
            lidar_topic:=/robot/scan
            warning_topic:=/too_close
        hil_timeout = 2.5
        hil_seed = 7
        """
    )
    pytester.makepyfile(
        f"""
        def test_fixtures(hil, hil_node, hil_link, hil_link_options, hil_config):
            assert hil_node.command == "{sys.executable} {STUDENT} correct"
            assert hil_node.params == ("lidar_topic:=/robot/scan", "warning_topic:=/too_close")
            assert hil_link == "ros2" and hil.link == "ros2"
            assert hil_link_options.node == hil_node.command
            assert hil_link_options.params == hil_node.params
            assert hil_link_options.scan_timeout == 0.75  # the command line's
            assert hil_link_options.ready_timeout == 20.0  # the default
            assert hil_link_options.domain_id is None and hil_link_options.port is None
            assert hil.seed == 7
            assert hil_config.source("node") == "hil_node in tox.ini"
        """
    )
    result = pytester.runpytest("--hil-timeout", "0.75")
    result.assert_outcomes(passed=1)


def test_a_conftest_overrides_the_node_fixture(pytester: pytest.Pytester) -> None:
    """A project can name its node in code; hil_link_options follows."""
    pytester.makeconftest(
        """
        import pytest
        from harness.pytest_plugin.plugin import NodeUnderTest

        @pytest.fixture
        def hil_node():
            return NodeUnderTest(package="my_pkg", executable="my_node", workspace="ws")
        """
    )
    pytester.makepyfile(
        """
        def test_options(hil_link_options):
            assert (hil_link_options.package, hil_link_options.executable) == ("my_pkg", "my_node")
            assert hil_link_options.workspace == "ws" and hil_link_options.node is None
        """
    )
    pytester.runpytest().assert_outcomes(passed=1)


def test_a_runs_problem_names_the_plugins_options(pytester: pytest.Pytester) -> None:
    """The link's own messages name options as the plugin does (--hil-workspace), a
    hil.run keyword by its name (node), never as the command line's flags."""
    pytester.makeconftest(
        """
        import pytest
        from harness.pytest_plugin.plugin import NodeUnderTest

        @pytest.fixture
        def hil_node():
            return NodeUnderTest(package="my_pkg", executable="my_node", workspace="nowhere")
        """
    )
    pytester.makepyfile(
        """
        def test_workspace(hil):
            hil.run("approach_wall")

        def test_node(hil):
            hil.run("approach_wall", node="python3 gone.py", package=None, executable=None)
        """
    )
    result = pytester.runpytest()
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(["*hil.run: --hil-workspace nowhere: no such folder"])
    result.stdout.fnmatch_lines(["*hil.run: node 'python3 gone.py': no such script gone.py"])


def test_hil_tests_skip_without_a_board_and_say_why(pytester: pytest.Pytester) -> None:
    pytester.makepyfile(
        """
        import pytest

        @pytest.mark.hil
        def test_on_board(hil_board):
            raise AssertionError("must not run")
        """
    )
    result = pytester.runpytest("-rs")
    result.assert_outcomes(skipped=1)
    result.stdout.fnmatch_lines(["*no physical board named: give --hil-port*"])


@pytest.fixture
def tty() -> Iterator[str]:
    """A serial device path (a pty slave) to name with --hil-port."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    yield path
    os.close(master)


def test_board_fixture_defaults_to_rplidar_and_the_boards_domain(
    pytester: pytest.Pytester, tty: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """--hil-port alone: an RPLIDAR board in domain 0 (or ROS_DOMAIN_ID); --hil-link picks LD."""
    port = tty
    pytester.makepyfile(
        f"""
        import pytest

        @pytest.mark.hil
        def test_board(hil_board, hil_link):
            assert (hil_board.port, hil_board.link, hil_board.domain_id) == ({port!r}, "rplidar", 0)
            assert hil_link == "ros2"  # other tests still run against their own node
            assert hil_board.run_options()["ros_network"] is True
        """
    )
    monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
    pytester.runpytest(f"--hil-port={port}").assert_outcomes(passed=1)
    pytester.makepyfile(
        """
        def test_board(hil_board):
            assert (hil_board.link, hil_board.domain_id) == ("ldlidar", 4)
        """
    )
    board = (f"--hil-port={port}", "--hil-link", "ldlidar", "--hil-domain-id", "4")
    pytester.runpytest(*board).assert_outcomes(passed=1)


def test_the_plugin_loads_no_ros_simulator_or_numpy(pytester: pytest.Pytester) -> None:
    """It is loaded into every pytest session of whoever installed the package."""
    pytester.makepyfile(
        """
        import sys

        def test_modules():
            assert "harness.pytest_plugin.plugin" in sys.modules
            heavy = [m for m in ("rclpy", "pybullet", "numpy") if m in sys.modules]
            assert heavy == []
        """
    )
    pytester.runpytest_subprocess(timeout=60).assert_outcomes(passed=1)
