"""Lockstep exchanges through each link: in-process, a ROS 2 node process, the virtual board."""

from __future__ import annotations

import itertools

import pytest

from harness.bench.stage import run_through
from harness.bench.workload import lab_workload
from harness.links.base import LinkOptions, create_link


def test_inprocess_lockstep_run(benchmark) -> None:
    """approach_wall through the inprocess link and the oracle (the whole loop, no DDS)."""
    workload = lab_workload(1, ("approach_wall",))
    with create_link("inprocess", LinkOptions(threshold=0.5)) as link:
        run = benchmark.pedantic(run_through, args=(link, workload), rounds=5)
    assert not run.result.failed_ticks


@pytest.mark.ros
def test_ros2_message(benchmark, scans) -> None:
    """A Scan turned into the LaserScan bytes the harness publishes."""
    from harness.ros.cdr import scan_cdr

    benchmark(scan_cdr, scans[0])


@pytest.mark.ros
def test_ros2_exchange(benchmark, ros2_link, scans) -> None:
    """One scan to the reference node and its answers back (publish, wait, take)."""
    ros2_link.warm_up(scans[0])
    ticks = itertools.count()
    cycle = itertools.cycle(scans)

    def exchange():
        return ros2_link.exchange(next(cycle), next(ticks))

    answers = benchmark(exchange)
    assert answers.statuses and not answers.timed_out


@pytest.mark.ros
def test_serial_exchange(benchmark, rplidar_link, scans) -> None:
    """One revolution down the emulated RPLIDAR line, the driver's /scan, the node's answers."""
    rplidar_link.warm_up(scans[0])
    ticks = itertools.count()
    cycle = itertools.cycle(scans)

    def exchange():
        return rplidar_link.exchange(next(cycle), next(ticks))

    answers = benchmark.pedantic(exchange, rounds=100)
    assert answers.statuses and not answers.timed_out
