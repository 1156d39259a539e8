"""How a scan travels: links deliver scans to the software under test and collect its answers.

``inprocess`` calls a processing function in a forked child; ``ros2`` drives a node
over a real ROS 2 graph; ``rplidar`` and ``ldlidar`` feed a board's driver an emulated
device on a serial line. What each link is lives once, in ``kinds`` (which imports
nothing); each link's module registers its class by name (``@register``), imported on
demand by ``create_link``, so the pure parts never import rclpy or pyserial. A new
link is a row in ``kinds`` and a module composing ``node_graph`` and ``node_exchange``
(no link subclasses another); a new serial LIDAR's module is ``board.serial_lidar``."""

from harness import lazy_exports

_EXPORTS = {
    "Link": "base",
    "LinkOptions": "base",
    "create_link": "base",
    "register": "base",
    "LinkKind": "kinds",
    "declare": "kinds",
    "link_kind": "kinds",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
