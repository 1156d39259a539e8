"""What a Dask worker that runs scenarios imports before it is forked: the run's side
(the simulation, the LIDAR, the judge, the ROS 2 link and its message types).

Importing this module is the whole of it. Commands whose tasks run scenarios in the
worker itself (sweep, hunt) name it to ``open_client``, whose embedded cluster forks
its workers from one multiprocessing fork server that has imported it: a cluster of
N workers pays these imports once instead of N times, and a worker Dask restarts
after a crash comes back warm. Nothing here starts a thread, a ROS context or a
simulation: those belong to each task.
"""

from __future__ import annotations

import contextlib
import importlib

WARM_MODULES = (
    "numpy",
    "harness.sim.bullet",  # pybullet, its banner swallowed
    "harness.runner.scenario_run",
    "harness.runner.suite",
    "harness.links.ros2",
    "harness.report.summary",
    "rclpy",
    "rclpy.node",
    "sensor_msgs.msg",
    "std_msgs.msg",
)

for _name in WARM_MODULES:
    with contextlib.suppress(ImportError):  # without the ros extra: the inprocess link alone
        importlib.import_module(_name)
