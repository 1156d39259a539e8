"""Links deliver scans to the software under test and collect its answers.

Each link lives in its own module here and registers itself by name with
``@register``; ``create_link("ros2", options)`` imports ``harness.links.ros2``
on demand, so the pure parts of the harness never import rclpy or pyserial.
"""

from harness.links.base import Link, LinkOptions, create_link, known_links, register

__all__ = ["Link", "LinkOptions", "create_link", "known_links", "register"]
