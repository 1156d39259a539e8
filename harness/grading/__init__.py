"""`fossbot-hil grade`: build and test a class's nodes, one student at a time or in parallel.

- ``discover``: which folders are students, and what each one handed in.
- ``process``: a child process that is bounded in time and output, and killable.
- ``build``: colcon build of one student into a scratch folder, and its first real error.
- ``worker``: one student's scenario suite, in its own process (``python -m``).
- ``grade``: the per-student pipeline (build, run, verdicts) and the parallel class loop.
- ``class_table``: the class table as CSV and HTML (pure).

Pure modules (``discover``, ``class_table``) import neither rclpy nor pybullet.
"""

from __future__ import annotations

__all__ = ["LAB_EXECUTABLE", "LAB_PACKAGE"]

LAB_PACKAGE = "fossbot_lidar_processing"
LAB_EXECUTABLE = "fossbot_lidar_node"
