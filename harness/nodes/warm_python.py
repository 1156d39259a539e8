"""What the fork server for students' nodes imports once: rclpy and the messages a lab
node uses, never a student's code (each forked node runs its script afresh, so an
edit is seen). A console script's entry-point scan is done once too, checked against
the files' times, so a rebuilt workspace is seen."""

from __future__ import annotations

import contextlib
import importlib
import importlib.metadata

_RCLPY = ("node", "executors", "qos", "logging", "parameter", "exceptions", "signals")
WARM_MODULES = ("math", "numpy", "rclpy", *(f"rclpy.{name}" for name in _RCLPY))
WARM_MODULES += ("sensor_msgs.msg", "std_msgs.msg", "geometry_msgs.msg")

for _name in WARM_MODULES:
    with contextlib.suppress(ImportError):  # a node that needs it will say so itself
        importlib.import_module(_name)

with contextlib.suppress(Exception):  # only a cache: a node does the lookup anyway
    for _distribution in importlib.metadata.distributions():  # fills the finders' caches
        pass
