"""Fixtures for the pytest-benchmark suite: worlds, scans and opened links, built once.

Run with ``pytest benchmarks/ -n 0`` (in one process, for timings; it is
outside the default ``testpaths``, so a plain ``pytest`` never runs it). Needs
the ``bench`` extra; the ROS 2 benchmarks need the ``ros`` extra too.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator

import numpy as np
import pytest

from harness.bench.workload import lab_workload, prepared_frames
from harness.lidar.scan import Scan
from harness.links.base import Link, LinkOptions, create_link


def pytest_configure(config: pytest.Config) -> None:
    if importlib.util.find_spec("pytest_benchmark") is None:
        raise pytest.UsageError("benchmarks/ needs pytest-benchmark: pip install -e '.[bench]'")


@pytest.fixture(scope="session")
def scans() -> list[Scan]:
    """The emitted scans of approach_wall, with its own faults and seed."""
    with prepared_frames(lab_workload(1, ("approach_wall",))) as frames:
        return [f.scan for f in frames]


@pytest.fixture(scope="session")
def truths() -> list[np.ndarray]:
    """The true ranges of approach_wall, tick by tick."""
    from harness.scenario.files import resolve_scenario
    from harness.sim.simulation import Simulation

    with Simulation(resolve_scenario("approach_wall")) as sim:
        return [t.truth for t in sim.ticks()]


@pytest.fixture(scope="module")
def captured_rays() -> Iterator[tuple[object, list[tuple[np.ndarray, np.ndarray]]]]:
    """An approach_wall simulation, run to its end, with every tick's rays."""
    from harness.scenario.files import resolve_scenario
    from harness.sim.simulation import Simulation

    with Simulation(resolve_scenario("approach_wall")) as sim:
        rays = []
        for _ in sim.ticks():
            rays.append(sim.lidar.rays())
        yield sim, rays


def _opened(name: str) -> Iterator[Link]:
    link = create_link(name, LinkOptions(threshold=0.5, scan_rate_hz=10.0))
    try:
        link.open()
        yield link
    finally:
        link.close()


@pytest.fixture(scope="module")
def ros2_link() -> Iterator[Link]:
    """The ros2 link with the bundled reference node running, opened once."""
    yield from _opened("ros2")


@pytest.fixture(scope="module")
def rplidar_link() -> Iterator[Link]:
    """The virtual board (emulated RPLIDAR, its driver, the node), opened once."""
    yield from _opened("rplidar")
