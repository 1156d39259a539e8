"""The software under test as processes: started, watched, stopped, reaped.

- ``command``: which command starts it (a script, a ROS package's
  executable, the bundled reference node) and its ``--ros-args``;
- ``process``: that command run as a ``NodeProcess``, with bounded start
  and stop, its output's tail kept;
- ``reaper``: the supervisor every node runs under, so nothing it starts
  outlives it; ``process_group`` stops a whole group;
- ``forkserver``: Python nodes forked warm from a process that has imported
  what they import (the bundled nodes; students' scripts and console
  scripts, from ``warm_python``); ``python_script`` decides which commands
  it may serve, so a forked node is what its command would have started;
- ``colcon_hooks``: the environment sourcing a colcon workspace would give;
- ``package_folder``: a package's source folder in a workspace, as colcon finds it;
- ``quick_exit``: ending a process without the interpreter's teardown.

No rclpy here: a node's ROS graph is ``harness.ros``'s.
"""

from harness import lazy_exports

_EXPORTS = {"NodeCommand": "command", "NodeProcess": "process"}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
