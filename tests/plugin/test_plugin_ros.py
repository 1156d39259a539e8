"""The plugin over real DDS: a generated test against the reference node and a student's node.

Each session runs in its own pytest process (as a user's would), and each
run starts its node in its own process, in a domain reserved for the run.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]
pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

STUDENT = Path(__file__).parents[1] / "ros" / "student_node.py"
# A generous per-scan deadline: a busy CI machine must not turn into a late answer.
SLACK = ("--hil-timeout", "5", "-p", "no:cacheprovider")

USER_TEST = """
def test_lab_scenario(hil):
    result = hil.run("rotate_beside_wall")
    print("domain", result.domain_id)
    assert result.ok, result.explanation
"""


def test_the_reference_node_passes_over_ros2(pytester: pytest.Pytester) -> None:
    """No node options: the bundled reference node, over ros2, in a reserved domain."""
    pytester.makepyfile(USER_TEST)
    result = pytester.runpytest_subprocess("-s", *SLACK, timeout=90)
    result.assert_outcomes(passed=1)
    domain = re.search(r"domain (\d+)", result.stdout.str())
    assert domain and 1 <= int(domain[1]) <= 101, result.stdout.str()
    assert "DeprecationWarning" not in result.stdout.str()  # ROS's own import noise is hidden


def test_a_buggy_node_fails_with_the_oracles_explanation(pytester: pytest.Pytester) -> None:
    """--hil-node names the student's node; the failure reads as the oracle's explanation."""
    pytester.makepyfile(USER_TEST)
    node = f"{sys.executable} {STUDENT} angle_in_degrees"
    result = pytester.runpytest_subprocess("--hil-node", node, *SLACK, timeout=90)
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(
        [
            "E *AssertionError: rotate_beside_wall over ros2 (seed 0, faults clean, "
            "threshold 0.5 m): 81 of 81 ticks failed",
            "E *first failure: t=0.00 s tick 0: nearest valid return 0.35 m at 1.566 rad*"
            "status 'Min distance: 0.350 m, angle: 89.7* gives 89.7* (looks like degrees*",
        ]
    )


def test_the_strict_warning_rule_from_the_option_and_per_run(pytester: pytest.Pytester) -> None:
    """A node publishing the Bool only when it is True: passes by default, fails under
    --hil-warning-when-clear required, and a run's own argument wins over the option."""
    pytester.makepyfile(
        """
        def test_default_rule(hil):
            assert hil.run("approach_wall", warning_when_clear="optional").ok

        def test_session_rule(hil):
            result = hil.run("approach_wall")
            assert "expected warning False; got no Bool" in result.explanation
            assert not result.ok
        """
    )
    node = f"{sys.executable} {STUDENT} correct_bool_when_close"
    result = pytester.runpytest_subprocess(
        "--hil-node", node, "--hil-warning-when-clear", "required", *SLACK, timeout=90
    )
    result.assert_outcomes(passed=2)
