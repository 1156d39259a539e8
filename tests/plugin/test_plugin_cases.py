"""The hil_scenarios marker: one test per scenario and fault profile, with readable ids."""

from __future__ import annotations

import pytest

from harness.scenario.files import shipped_scenarios

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(60)


def collected(result: pytest.RunResult) -> list[str]:
    return [line for line in result.stdout.lines if "::" in line]


def test_names_times_faults_with_readable_ids(pytester: pytest.Pytester) -> None:
    pytester.makepyfile(
        test_cases="""
        import pytest

        @pytest.mark.hil_scenarios("approach_wall", "out_of_range", faults=["clean", "noisy"])
        def test_x(hil_case):
            assert hil_case.faults in ("clean", "noisy")
        """
    )
    result = pytester.runpytest("--collect-only", "-q")
    assert collected(result) == [
        "test_cases.py::test_x[approach_wall-clean]",
        "test_cases.py::test_x[approach_wall-noisy]",
        "test_cases.py::test_x[out_of_range-clean]",
        "test_cases.py::test_x[out_of_range-noisy]",
    ]
    pytester.runpytest().assert_outcomes(passed=4)


def test_no_names_is_every_shipped_scenario_with_its_own_faults(pytester: pytest.Pytester) -> None:
    """On a class, for every method; the id is the scenario alone when faults are its own."""
    pytester.makepyfile(
        test_all="""
        import pytest

        @pytest.mark.hil_scenarios()
        class TestShipped:
            def test_x(self, hil_case):
                assert hil_case.faults is None and hil_case.id == hil_case.scenario
        """
    )
    result = pytester.runpytest("--collect-only", "-q")
    names = [s.name for s in shipped_scenarios()]
    assert collected(result) == [f"test_all.py::TestShipped::test_x[{n}]" for n in names]
    assert len(names) == 7


def test_a_scenario_file_and_combined_faults(pytester: pytest.Pytester) -> None:
    """A path is named by its stem; "a,b" combines profiles, as --faults does."""
    pytester.makefile(
        ".yaml",
        beside_wall=(
            "description: Beside a wall.\n"
            "obstacles: [{type: wall, start: [0.4, -1.0], end: [0.4, 1.0]}]\n"
            "motion: {segments: [{until: {duration: 0.5}}]}\n"
        ),
    )
    pytester.makepyfile(
        test_file="""
        import pytest

        @pytest.mark.hil_scenarios("./beside_wall.yaml", faults="noisy,dropouts_nan")
        def test_x(hil_case):
            pass
        """
    )
    result = pytester.runpytest("--collect-only", "-q")
    assert collected(result) == ["test_file.py::test_x[beside_wall-noisy,dropouts_nan]"]


@pytest.mark.parametrize(
    ("marker", "signature", "message"),
    [
        ('"approach_wal"', "hil_case", "unknown scenario 'approach_wal' (shipped: approach_wall"),
        ('faults=["none"]', "hil_case", "faults[0]: unknown fault profile 'none' (known: clean"),
        ("faults=3", "hil_case", "faults= must be a profile name or a list of them"),
        ('fault="noisy"', "hil_case", "unknown argument 'fault' (known: faults)"),
        ('"approach_wall"', "hil", "on test_x: the test needs a hil_case argument"),
    ],
)
def test_marker_mistakes_are_one_collection_error(
    pytester: pytest.Pytester, marker: str, signature: str, message: str
) -> None:
    pytester.makepyfile(
        f"""
        import pytest

        @pytest.mark.hil_scenarios({marker})
        def test_x({signature}):
            pass
        """
    )
    result = pytester.runpytest()
    result.assert_outcomes(errors=1)
    # The short summary repeats the message in full where CI is set (pytest
    # does not cut it there); the error report itself is the one line that counts.
    lines = [
        line for line in result.stdout.lines if message in line and not line.startswith("ERROR ")
    ]
    assert len(lines) == 1 and lines[0].startswith("@pytest.mark.hil_scenarios"), lines
    assert "Traceback" not in result.stdout.str() and "harness/" not in result.stdout.str()


def test_hil_case_without_the_marker_says_where_it_comes_from(pytester: pytest.Pytester) -> None:
    pytester.makepyfile("def test_x(hil_case):\n    pass\n")
    result = pytester.runpytest()
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*hil_case comes from @pytest.mark.hil_scenarios(...)*"])
