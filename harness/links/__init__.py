"""How a scan travels: links deliver scans to the software under test and collect its answers.

- ``inprocess``: a processing function, called in a forked child
  (``processor_child``);
- ``ros2``: a node in its own process, over a real ROS 2 graph;
- ``rplidar``, ``ldlidar``: a board's driver reading an emulated device on a
  serial line (``board``), its nodes answering over ROS 2.

Each link lives in its own module here and registers itself by name with
``@register``; ``create_link("ros2", options)`` imports ``harness.links.ros2``
on demand, so the pure parts of the harness never import rclpy or pyserial.
A new link is a new module with a ``Link`` subclass (``base``); a module that
several links share is named in ``base.HELPER_MODULES``.
"""

from harness.links.base import Link, LinkOptions, create_link, known_links, register

__all__ = ["Link", "LinkOptions", "create_link", "known_links", "register"]
