"""The fossbot-hil pytest plugin (registered by entry point; no conftest needed).

For now it selects a physical board for hardware-in-the-loop tests: tests
marked ``hil`` run against the board named with ``--hil-port`` and skip,
saying why, where none is given. Never opens a port that was not named.
"""

from __future__ import annotations

from dataclasses import dataclass

import pytest

NO_BOARD = (
    "no physical board named: give --hil-port /dev/ttyUSB0 (the USB-UART wired to the "
    "board's LIDAR input) and --hil-domain-id N (the board's ROS_DOMAIN_ID)"
)


@dataclass(frozen=True)
class HilBoard:
    """Where the board is: the adapter wired to its LIDAR input, and its ROS graph."""

    port: str
    domain_id: int
    link: str  # the device the board expects: rplidar or ldlidar


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("fossbot-hil", "FOSSBot hardware-in-the-loop")
    group.addoption(
        "--hil-port",
        metavar="DEV",
        default=None,
        help="USB-UART wired to the board's LIDAR input (enables hil tests)",
    )
    group.addoption(
        "--hil-domain-id",
        metavar="N",
        type=int,
        default=None,
        help="the board's ROS_DOMAIN_ID (default 0)",
    )
    group.addoption(
        "--hil-link",
        default="rplidar",
        choices=["rplidar", "ldlidar"],
        help="which LIDAR the board expects (default rplidar)",
    )


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "hil: needs a physical FOSSBot board (--hil-port)")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if config.getoption("--hil-port") is not None:
        return
    skip = pytest.mark.skip(reason=NO_BOARD)
    for item in items:
        if item.get_closest_marker("hil"):
            item.add_marker(skip)


@pytest.fixture
def hil_board(request: pytest.FixtureRequest) -> HilBoard:
    """The board selected on the command line (hil tests only run when there is one)."""
    config = request.config
    port = config.getoption("--hil-port")
    if port is None:
        pytest.skip(NO_BOARD)
    domain = config.getoption("--hil-domain-id")
    return HilBoard(port, 0 if domain is None else domain, config.getoption("--hil-link"))
