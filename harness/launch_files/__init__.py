"""A ROS package's launch files, read without running them, held against the running node.

``launch`` and ``launch_ros`` are not installable here (and a student's launch file
should not run inside the harness), yet the lab asks for one, and its own listing
passes a parameter the node never declares. So the files are read as text
(``reading`` picks the reader: ``python_file``, ``xml_file``, ``yaml_file``) and the
running node is asked what it declares (``harness.ros.parameters``); ``checks`` words
the advice, ``run_check`` holds a run's state, ``launch_command`` runs ``ros2 launch``."""

from harness import lazy_exports

_EXPORTS = {
    "LaunchCheck": "run_check",
    "LaunchFile": "entries",
    "NodeEntry": "entries",
    "read_launch_file": "reading",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
