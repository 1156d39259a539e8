"""A ROS package's launch files, read without running them, held against the running node.

ROS 2's ``launch`` and ``launch_ros`` are not installable here (and a
student's launch file should not run inside the harness anyway), yet the
lab asks for one, and its own listing passes a parameter the node never
declares. So the files are read as text and the running node is asked
which parameters it declares:

- ``entries``: what a launch file says (its nodes, their parameters, with
  lines; and what cannot be known without running it);
- ``finding``: which launch files a package has (its source ``launch/``
  folder, or the installed ``share/<pkg>/launch``);
- ``python_file``, ``xml_file``, ``yaml_file``: reading each kind (``reading``
  picks by file name);
- ``checks``: the advice: a package or executable the build lacks, a
  parameter the node does not declare (with the closest it does);
- ``run_check``: the once-per-run state a ros2 link keeps (``LaunchCheck``);
- ``launch_command``: ``run --launch PACKAGE FILE`` through ``ros2 launch``.

No rclpy here: asking the node is ``harness.ros.parameters``'s.
"""

from harness import lazy_exports

_EXPORTS = {
    "LaunchCheck": "run_check",
    "LaunchFile": "entries",
    "NodeEntry": "entries",
    "read_launch_file": "reading",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
