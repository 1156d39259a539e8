"""Shared settings for the harness's own tests.

The ROS 2 tests run real nodes over real DDS. Where rclpy is missing they
must not pass silently by skipping: the run stops with the reason, unless
they were deselected on purpose (``pytest -m "not ros"``).
"""

from __future__ import annotations

import importlib.util

import pytest


@pytest.hookimpl(trylast=True)  # after -m has deselected what the user left out
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    wants_ros = [item for item in items if item.get_closest_marker("ros")]
    if wants_ros and importlib.util.find_spec("rclpy") is None:
        raise pytest.UsageError(
            f"{len(wants_ros)} selected tests need rclpy and Fast DDS, which are not installed: "
            "pip install '.[ros]' (or source ROS 2 Jazzy), or deselect them with -m 'not ros'"
        )
