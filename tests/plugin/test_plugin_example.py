"""examples/: the suite users copy runs as its README says (here through the inprocess link)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]
pytestmark = pytest.mark.timeout(60)

EXAMPLES = Path(__file__).parents[2] / "examples"


def test_the_example_suite_passes_where_it_is_copied(pytester: pytest.Pytester) -> None:
    """Copied into a project with no conftest: 14 tests, the marker's ids, all passing."""
    for name in ("test_my_node.py", "narrow_corridor.yaml"):
        shutil.copy(EXAMPLES / name, pytester.path / name)
    result = pytester.runpytest_subprocess(
        "--hil-link", "inprocess", "-v", "-p", "no:cacheprovider", timeout=50
    )
    result.assert_outcomes(passed=14)
    result.stdout.fnmatch_lines(
        ["*test_lab_scenarios_under_faults?obstacle_at_side-dropouts_nan? PASSED*"]
    )
