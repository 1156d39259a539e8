"""The software under test as processes: started, watched, stopped, reaped.

``command`` says what starts it, ``process`` runs it (bounded start and stop, its
output's tail), under the ``reaper`` so nothing it starts outlives it; ``forkserver``
forks Python nodes warm (``python_script`` decides which). No rclpy here: a node's ROS
graph is ``harness.ros``'s."""

from harness import lazy_exports

_EXPORTS = {"NodeCommand": "command", "NodeProcess": "process"}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
