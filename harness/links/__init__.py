"""How a scan travels: links deliver scans to the software under test and collect its answers.

- ``inprocess``: a processing function, called in a forked child
  (``processor_child``);
- ``ros2``: a node in its own process, over a real ROS 2 graph;
- ``rplidar``, ``ldlidar``: a board's driver reading an emulated device on a
  serial line (``board``), its nodes answering over ROS 2.

What each link is (runs a node, uses a serial line, which device) is
declared once, in ``kinds``: a table that imports nothing, from which every
list of links the commands and the pytest plugin show is derived. Each
link's class lives in its own module here and registers itself by name with
``@register``, checked against its row; ``create_link("ros2", options)``
imports ``harness.links.ros2`` on demand, so the pure parts of the harness
never import rclpy or pyserial. A new link is a row in ``kinds`` and a new
module with a ``Link`` subclass (``base``), composing what links share
(``node_graph``, ``node_exchange``) rather than subclassing another link; a
new serial LIDAR's module registers its name with its device profile
(``board.serial_lidar``). One from outside the harness calls ``kinds.declare``.
"""

from harness import lazy_exports

_EXPORTS = {
    "Link": "base",
    "LinkOptions": "base",
    "create_link": "base",
    "known_links": "base",
    "register": "base",
    "LinkKind": "kinds",
    "declare": "kinds",
    "link_kind": "kinds",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
