"""What a Dask worker that runs scenarios imports before it is forked: the run's side
(the simulation, the LIDAR, the judge, the report).

Importing this module is the whole of it. Commands whose tasks run scenarios in the
worker itself (sweep, hunt) name it to ``open_client``, whose embedded cluster forks
its workers from one multiprocessing fork server that has imported it: a cluster of
N workers pays these imports once instead of N times, and a worker Dask restarts
after a crash comes back warm. Nothing here may start a thread, a ROS context or a
simulation: a fork keeps only the thread that forks, so a worker would inherit the
locks other threads held. That leaves rclpy out: importing it starts the two listener
threads of LTTng-UST (the tracing library its middleware's wheels bundle), so each
worker imports it itself. numpy's OpenBLAS thread is Dask's own preload's too, and forks
safely (OpenBLAS resets its pool in the child).
"""

from __future__ import annotations

import numpy  # noqa: F401

import harness.report.summary  # noqa: F401
import harness.runner.scenario_run  # noqa: F401
import harness.runner.suite  # noqa: F401
import harness.sim.bullet  # noqa: F401  (pybullet, its banner swallowed)
