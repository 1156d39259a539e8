"""What a Dask worker that runs scenarios imports before it is forked (importing is all).

An embedded cluster forks its workers from one fork server that imported
this, so N workers pay these imports once and a restarted worker comes back
warm. Nothing here may start a thread, a ROS context or a simulation (a
fork keeps only the forking thread): so not rclpy, whose LTTng-UST starts
two threads on import. numpy's OpenBLAS forks safely.
"""

from __future__ import annotations

import numpy  # noqa: F401

import harness.report.summary  # noqa: F401
import harness.runner.scenario_run  # noqa: F401
import harness.runner.suite  # noqa: F401
import harness.sim.bullet  # noqa: F401  (pybullet, its banner swallowed)
