"""A serial LIDAR that exists only in the tests: what a new one needs, and nothing else.

Each of its parts sits where docs/architecture.md's "where to add" puts a
new LIDAR's, here outside the harness: ``codec`` (its protocol, pure, as in
``harness/devices/``), ``preset`` (its beam layout and its device profile,
made known by ``harness.lidar.spec.add_preset`` and
``harness.devices.profiles.add_profile``), ``link`` (the link module, as in
``harness/links/``) and ``driver`` (the board's driver that reads it, as the
bundled ones in ``node/fossbot_lidar_driver``). Importing this package makes
the LIDAR known to the harness: its row in the link table
(``harness.links.kinds.declare``, the one line ``kinds.KINDS`` holds for a
shipped link) costs no import of the link class.
"""

from harness.links.kinds import LinkKind, declare
from toy_lidar.preset import PROFILE, SPEC

KIND = declare(
    LinkKind("toylidar", "toy_lidar.link", runs_node=True, serial_line=True, device=PROFILE.name)
)
NAME = KIND.name
PRESET = SPEC.name

__all__ = ["KIND", "NAME", "PRESET"]
