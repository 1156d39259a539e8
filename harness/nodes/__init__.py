"""The software under test as processes: started, watched, stopped, reaped.

- ``command``: which command starts it (a script, a ROS package's
  executable, the bundled reference node) and its ``--ros-args``;
- ``process``: that command run as a ``NodeProcess``, with bounded start
  and stop, its output's tail kept;
- ``reaper``: the supervisor every node runs under, so nothing it starts
  outlives it; ``process_group`` stops a whole group;
- ``forkserver``: the bundled nodes forked warm from a process that has
  imported them;
- ``quick_exit``: ending a process without the interpreter's teardown.

No rclpy here: a node's ROS graph is ``harness.ros``'s.
"""

from harness import lazy_exports

_EXPORTS = {"NodeCommand": "command", "NodeProcess": "process"}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
