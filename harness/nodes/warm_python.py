"""What the fork server for students' nodes imports once: rclpy and the messages a lab
node uses, never a student's code.

Importing this module is the whole of the server's preparation; each node
forked from it then reads and runs the student's script afresh, so an edit
is always seen. Its imports are the ones every Lab 07 node makes (rclpy, the
executors, QoS, LaserScan, String, Bool) and the ones a node often makes
(numpy, math). The scan of installed distributions that a colcon console
script does to find its entry point is done once too, so each node finds its
entry point in the server's warm cache (checked against the files' times,
so a rebuilt workspace is seen).
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.metadata

WARM_MODULES = (
    "math",
    "numpy",
    "rclpy",
    "rclpy.node",
    "rclpy.executors",
    "rclpy.qos",
    "rclpy.logging",
    "rclpy.parameter",
    "rclpy.exceptions",
    "rclpy.signals",
    "sensor_msgs.msg",
    "std_msgs.msg",
    "geometry_msgs.msg",
)

for _name in WARM_MODULES:
    with contextlib.suppress(ImportError):  # a node that needs it will say so itself
        importlib.import_module(_name)

with contextlib.suppress(Exception):  # only a cache: a node does the lookup anyway
    for _distribution in importlib.metadata.distributions():  # fills the finders' caches
        pass
