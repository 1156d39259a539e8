"""The plugin checks topics and parameters as the command line does (one checker for both).

A bad name or a parameter that fights the harness fails that test with one
line naming hil.run's argument; a parameter given twice on the command line
stops the session. Runs pytest inside pytest over the inprocess link; nothing
here starts ROS.
"""

from __future__ import annotations

import pytest

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(60)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            'scan_topic="not a topic"',
            "hil.run: scan_topic='not a topic': topic name must not contain characters other",
        ),
        ('status_topic=""', "hil.run: status_topic='': topic name must not be empty"),
        ('scan_topic="/a//b"', "hil.run: scan_topic='/a//b': topic name must not contain rep"),
        ('warning_topic="~/warn"', "hil.run: warning_topic='~/warn': a private name (~)"),
        ("scan_topic=5", "hil.run: scan_topic=5: a topic name must be text, got int"),
        (
            'status_topic="scan"',
            "hil.run: status_topic='scan': the same topic as scan_topic='/scan' (/scan)",
        ),
        (
            'threshold=0.4, params=["threshold:=0.1"]',
            "hil.run: params='threshold:=0.1' sets 'threshold', the parameter the harness passes",
        ),
        (
            'threshold_param="min_dist", params=["min_dist:=0.1"]',
            "hil.run: params='min_dist:=0.1' sets 'min_dist', the parameter the harness passes "
            "the threshold in (threshold, default the scenario's): the node and the oracle would "
            "disagree; use threshold=0.1 instead (or threshold_param='' if the node must not get "
            "the threshold)",
        ),
        ('params=["a:=1", "a:=2"]', "hil.run: params='a:=1' and params='a:=2' set the same"),
        ('params=["1a:=1"]', "hil.run: params: ROS 2 cannot parse '1a:=1': a parameter name"),
        ('params="a:=1"', "hil.run: params must be a list of NAME:=VALUE items, got 'a:=1'"),
        (
            'threshold_param="bad name!"',
            "hil.run: threshold_param='bad name!': a parameter name is words",
        ),
    ],
)
def test_bad_names_fail_the_test_with_one_line(
    pytester: pytest.Pytester, call: str, message: str
) -> None:
    pytester.makepyfile(f"def test_bad(hil):\n    hil.run('approach_wall', {call})\n")
    result = pytester.runpytest("--hil-link", "inprocess")
    result.assert_outcomes(failed=1)
    lines = [line for line in result.stdout.lines if message in line]
    assert lines and lines[0].startswith(message), result.stdout.str()
    assert "harness/" not in result.stdout.str() and "Traceback" not in result.stdout.str()


def test_relative_topics_resolve_and_no_threshold_param_frees_the_name(
    pytester: pytest.Pytester,
) -> None:
    """`scan` is `/scan`; with threshold_param=None the node's threshold is the user's."""
    pytester.makepyfile(
        "from harness.pytest_plugin.hil import Hil\n"
        "def test_ok(hil):\n"
        "    options = hil._checked('approach_wall', None, None, None, 'inprocess', None,\n"
        "        {'scan_topic': 'robot/scan', 'threshold_param': None,\n"
        "         'params': ['threshold:=0.1']})[2]\n"
        "    assert options.scan_topic == '/robot/scan'\n"
        "    assert options.params == ('threshold:=0.1',)\n"
        "    assert hil.run('approach_wall', status_topic='lidar_status').ok\n"
    )
    pytester.runpytest("--hil-link", "inprocess").assert_outcomes(passed=1)


def test_a_parameter_given_twice_stops_the_session(pytester: pytest.Pytester) -> None:
    pytester.makepyfile("def test_never_runs(): raise AssertionError")
    result = pytester.runpytest("--hil-param", "lidar_topic:=/a", "--hil-param", "lidar_topic:=/b")
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    message = "--hil-param 'lidar_topic:=/a' and --hil-param 'lidar_topic:=/b' set the same"
    assert [line for line in result.stderr.lines if message in line], result.stderr.str()
    assert "Traceback" not in result.stderr.str()
