"""A node that cannot start because of how it was set up, not because of its code (pure).

A node run with a Python that lacks rclpy dies on its first import: a configuration
error naming which interpreter lacks what and which has it, not a scenario's ERROR."""

from __future__ import annotations

import re
import sys
from collections.abc import Sequence
from pathlib import Path

# ROS 2's Python packages by their names: rclpy and its kin, message, service and
# interface packages (rcl_interfaces is what lab nodes often import first), ament.
ROS_MODULE = re.compile(
    r"(rclpy|rcl_\w+|rosidl_\w+|ament_\w+|tf2_\w+|launch(_ros)?|\w+_(msgs|srvs|interfaces))$"
)
_MISSING = re.compile(r"ModuleNotFoundError: No module named '([A-Za-z_][\w.]*)'")
PYTHON = re.compile(r"python(\d+(\.\d+)?)?$")


def is_ros_module(name: str) -> bool:
    """Is `name` (dotted or not) one of ROS 2's Python packages, by its top-level name?"""
    return bool(ROS_MODULE.match(name.split(".")[0]))


def is_python(program: str) -> bool:
    """Does `program` (a path or a name) look like a Python interpreter?"""
    return bool(PYTHON.match(Path(program).name))


def setup_problem(output: str, argv: Sequence[str]) -> str | None:
    """The setup mistake `output` (the node's last stderr lines, its exit summary) shows,
    in one line with the fix; None when the node failed for a reason of its own."""
    missing = _MISSING.search(output)
    if missing is None or not is_ros_module(missing[1]):
        return None
    module = missing[1].split(".")[0]
    program = argv[0] if argv else "the node's interpreter"
    fix = (
        f"this harness's Python ({sys.executable}), activate the harness's virtual environment, "
        "or source ROS 2 Jazzy"
    )
    if argv and is_python(program):
        return f"the node's Python ({program}) cannot import {module}: run the node with {fix}"
    return f"the node cannot import {module} (ModuleNotFoundError): start it with {fix}"
