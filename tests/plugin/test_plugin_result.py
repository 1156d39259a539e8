"""hil.run and its result, through the inprocess link (no ROS): what a failing test prints."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(60)

STUDENT_FUNCTIONS = Path(__file__).parents[1] / "student_functions.py"


def test_a_passing_run_and_its_record(pytester: pytest.Pytester) -> None:
    """The reference processing passes; the JUnit report carries one property per run."""
    pytester.makepyfile(
        """
        def test_wall(hil):
            result = hil.run("approach_wall", threshold=0.4, faults="noisy", seed=3)
            assert result.ok, result.explanation
            assert result.raw.threshold == 0.4 and result.raw.faults == "noisy"
            assert result.raw.seed == 3 and result.domain_id is None
            assert result.failed_ticks == [] and len(result.records) == 95
            assert repr(result) == "<HilResult approach_wall over inprocess: PASS, 95 ticks>"
            assert result.explanation.endswith(": all 95 ticks passed")
            assert result.check() is result
        """
    )
    result = pytester.runpytest("--hil-link", "inprocess", "--junitxml", "report.xml")
    result.assert_outcomes(passed=1)
    report = (pytester.path / "report.xml").read_text()
    assert '<property name="hil" value="approach_wall over inprocess: PASS" />' in report


def test_a_failing_run_explains_the_first_failure_and_counts_the_rest(
    pytester: pytest.Pytester,
) -> None:
    """`assert result.ok, result.explanation`: the oracle's words, not a dump."""
    pytester.makepyfile(
        f"""
        def test_degrees(hil):
            result = hil.run(
                "rotate_beside_wall", processor="{STUDENT_FUNCTIONS}:angle_in_degrees"
            )
            assert result.ok, result.explanation
        """
    )
    result = pytester.runpytest("--hil-link", "inprocess")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(
        [
            "E   *AssertionError: rotate_beside_wall over inprocess (seed 0, faults clean, "
            "threshold 0.5 m): * of 81 ticks failed",
            "E   *first failure: t=0.00 s tick 0: nearest valid return 0.35 m at 1.566 rad*"
            "(looks like degrees: 1.5664 rad is 89.7°)",
            "E   *more failed ticks: *, ...",
        ]
    )


def test_a_bare_assert_shows_the_short_repr(pytester: pytest.Pytester) -> None:
    """Assertion rewriting prints the repr: verdict and counts, one short line (the
    explanation is the assert message's or check()'s, never printed twice)."""
    pytester.makepyfile(
        f"""
        def test_bool(hil):
            assert hil.run("approach_wall", processor="{STUDENT_FUNCTIONS}:inverted_bool").ok

        def test_check(hil):
            hil.run("approach_wall", processor="{STUDENT_FUNCTIONS}:inverted_bool").check()
        """
    )
    result = pytester.runpytest("--hil-link", "inprocess")
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(
        [
            "E * where False = <HilResult approach_wall over inprocess: FAIL, "
            "* of 95 ticks failed>.ok",
            "E *AssertionError: approach_wall over inprocess (seed 0, *",
        ]
    )


def test_a_scenario_file_next_to_the_test(pytester: pytest.Pytester) -> None:
    """A relative path is found from the working directory or, failing that, the test file."""
    folder = pytester.mkpydir("suite")
    (folder / "beside_wall.yaml").write_text(
        "description: Beside a wall.\n"
        "obstacles: [{type: wall, start: [0.4, -1.0], end: [0.4, 1.0]}]\n"
        "motion: {segments: [{until: {duration: 0.5}}]}\n"
    )
    (folder / "test_file.py").write_text(
        "def test_file(hil):\n"
        "    result = hil.run('beside_wall.yaml')\n"
        "    assert result.ok and result.scenario == 'beside_wall', result.explanation\n"
    )
    pytester.runpytest("--hil-link", "inprocess").assert_outcomes(passed=1)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        ('"approach_wal"', "hil.run: unknown scenario 'approach_wal' (shipped: approach_wall, "),
        ('"approach_wall", faults="nosy"', "hil.run: faults[0]: unknown fault profile 'nosy'"),
        ('"approach_wall", threshold=-1', "hil.run: threshold must be a positive number"),
        ('"approach_wall", seed=-1', "hil.run: seed must be a whole number in 0..2**32-1"),
        ('"approach_wall", timeout=2', "hil.run: unknown option 'timeout' (known: link, "),
        ('"approach_wall", link="serial"', "hil.run: unknown link 'serial' (known: inprocess"),
        ('"approach_wall", processor="nope.py:f"', "hil.run: processor 'nope.py:f': no such"),
        ('"approach_wall", scan_timeout=1e9', "hil.run: scan_timeout must be at most 86400"),
        ('"approach_wall", scan_timeout="1"', "hil.run: scan_timeout must be a number, got '1'"),
        ('"approach_wall", ready_timeout=0', "hil.run: ready_timeout must be a positive number"),
        ('"approach_wall", domain_id=1.5', "hil.run: domain_id must be a whole number 0..232"),
        (
            '"approach_wall", threshold=99',
            "hil.run: threshold for scenario approach_wall: 99 m",
        ),
    ],
)
def test_bad_arguments_fail_the_test_with_one_line(
    pytester: pytest.Pytester, call: str, message: str
) -> None:
    """A typo in the test is the test's failure, told in one line, no harness traceback."""
    pytester.makepyfile(f"def test_bad(hil):\n    hil.run({call})\n")
    result = pytester.runpytest("--hil-link", "inprocess")
    result.assert_outcomes(failed=1)
    lines = [line for line in result.stdout.lines if message in line]
    assert lines and lines[0].startswith(message), result.stdout.str()
    assert "harness/" not in result.stdout.str() and "Traceback" not in result.stdout.str()
