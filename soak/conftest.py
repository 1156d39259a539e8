"""The soak suite: the scenario suite many times in a row, to find flakes.

Run with ``pytest soak/ --soak-runs 20`` (outside the default ``testpaths``,
so a plain ``pytest`` never runs it). Each round is a real ``fossbot-hil
run`` process with its own report folder; the summary names every round
that failed and the slowest one.
"""

from __future__ import annotations

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--soak-runs", type=int, default=20, help="rounds per link (default 20)")
    parser.addoption(
        "--soak-links",
        default="ros2,inprocess,rplidar",
        help="links to soak, comma separated (default ros2,inprocess,rplidar)",
    )


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    if "soak_link" in metafunc.fixturenames:
        links = [x.strip() for x in metafunc.config.getoption("--soak-links").split(",")]
        metafunc.parametrize("soak_link", [x for x in links if x])


@pytest.fixture
def soak_runs(request: pytest.FixtureRequest) -> int:
    runs = request.config.getoption("--soak-runs")
    if runs < 1:
        raise pytest.UsageError("--soak-runs must be at least 1")
    return runs
