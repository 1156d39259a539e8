"""Shared settings for the harness's own tests.

The ROS 2 tests run real nodes over real DDS. Where rclpy is missing they
must not pass silently by skipping: the run stops with the reason, unless
they were deselected on purpose (``pytest -m "not ros"``).
"""

from __future__ import annotations

import importlib.util
import os
import sys
from collections.abc import Iterator

import pytest


def pytest_configure(config: pytest.Config) -> None:
    """Let the suite's processes keep their bytecode. A machine that sets
    PYTHONDONTWRITEBYTECODE (CI's image does) makes every process the suite starts
    (thousands: the command, nodes, Dask workers) compile the harness from source
    again, about 0.2 s of CPU each: 7 % of a command-heavy part of the suite."""
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)  # before xdist starts its workers
    sys.dont_write_bytecode = False


@pytest.fixture(autouse=True, scope="session")
def _own_cache_folder(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Every `fossbot-hil run` keeps its verdicts in the user's cache folder
    (docs/watch.md): the suite's runs keep theirs in a folder of the session's own,
    so they never reorder a user's own runs (nor the user's theirs)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("FOSSBOT_HIL_CACHE_DIR", str(tmp_path_factory.mktemp("fossbot-hil-cache")))
        yield


@pytest.fixture(autouse=True, scope="session")
def _cli_names() -> Iterator[None]:
    """Lower layers' messages name options as the CLI does (--port, --lidar-mount), the
    way `fossbot-hil` speaks them; a test of another caller speaks its own."""
    from harness.cli import build_parser, flag_names
    from harness.option_names import speaking

    with speaking(flag_names(build_parser())):
        yield


@pytest.hookimpl(optionalhook=True)  # pytest-xdist's hook
def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """`-n auto`: one worker more than cores. About a third of the suite's time is
    spent waiting (nodes starting, DDS discovery, deadlines, paced serial lines),
    not computing, so one more worker keeps the cores busy."""
    return len(os.sched_getaffinity(0)) + 1


@pytest.hookimpl(trylast=True)  # after -m has deselected what the user left out
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    wants_ros = [item for item in items if item.get_closest_marker("ros")]
    if wants_ros and importlib.util.find_spec("rclpy") is None:
        raise pytest.UsageError(
            f"{len(wants_ros)} selected tests need rclpy and Fast DDS, which are not installed: "
            "pip install '.[ros]' (or source ROS 2 Jazzy), or deselect them with -m 'not ros'"
        )
    # The longest tests first (a stable sort keeps the rest in order): started
    # last, one of them would run on alone while the other workers sit idle.
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)
