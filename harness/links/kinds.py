"""What each link is, declared once: a table cheap enough for a command's start.

Every list of links the CLI, the pytest plugin, grade, audit, hunt, emulate and the
messages show is derived from ``KINDS``; asking the link classes instead would
import rclpy, pyserial and numpy (about 0.2 s) everywhere. Each class's ClassVars
are checked against its row when it registers (``base.register``). A link from
outside the harness calls ``declare`` before it is named."""

from __future__ import annotations

from dataclasses import dataclass

from harness.errors import ConfigError

__all__ = [
    "INPROCESS",
    "KINDS",
    "ROS2",
    "LinkKind",
    "declare",
    "default_link",
    "default_serial_link",
    "device_names",
    "either",
    "link_kind",
    "link_names",
    "node_links",
    "serial_links",
]


@dataclass(frozen=True)
class LinkKind:
    """One link: where its class lives and what it is, for those who must not import it."""

    name: str
    module: str  # imported on the link's first use; it registers the class as `name`
    # Starts the software under test as a node process on a ROS 2 graph (its own
    # domain); the other kind calls a processing function (--processor).
    runs_node: bool
    # Scans travel as device bytes on a serial line, to a board (virtual on a pty, or
    # physical with --port) whose driver publishes them: --port, --board-command and
    # --lidar-mount apply.
    serial_line: bool = False
    # Serial links: the device profile (harness.devices.profiles) it emulates, also
    # the name `fossbot-hil emulate` serves it under.
    device: str | None = None
    default: bool = False  # the link a run takes when none is named
    # Started by `ros2 launch` when asked (--launch): the node is the harness's own
    # graph's only software, which a board's driver is not.
    launches: bool = False


INPROCESS = "inprocess"
ROS2 = "ros2"

KINDS: dict[str, LinkKind] = {
    kind.name: kind
    for kind in (
        LinkKind(INPROCESS, "harness.links.inprocess", runs_node=False),
        LinkKind(ROS2, "harness.links.ros2", runs_node=True, default=True, launches=True),
        # The first serial link is the one a board run takes when none is named.
        LinkKind(
            "rplidar", "harness.links.rplidar", runs_node=True, serial_line=True, device="rplidar"
        ),
        LinkKind(
            "ldlidar", "harness.links.ldlidar", runs_node=True, serial_line=True, device="ldlidar"
        ),
    )
}


def declare(kind: LinkKind) -> LinkKind:
    """Make a link from outside this package known (once); returns it."""
    known = KINDS.get(kind.name)
    if known is not None and known != kind:
        raise RuntimeError(f"link {kind.name!r} is declared twice")
    if kind.serial_line != (kind.device is not None):
        raise RuntimeError(f"link {kind.name!r}: a serial link names its device, no other does")
    KINDS[kind.name] = kind
    return kind


def link_names() -> list[str]:
    """Every known link, sorted."""
    return sorted(KINDS)


def link_kind(name: str) -> LinkKind:
    """The declaration of `name`, or a ConfigError listing the known links."""
    kind = KINDS.get(name)
    if kind is None:
        raise ConfigError(f"unknown link {name!r} (known: {', '.join(link_names())})")
    return kind


def node_links() -> list[str]:
    """The links that start a node (grade, audit: a student's code is a node), in
    declaration order."""
    return [kind.name for kind in KINDS.values() if kind.runs_node]


def serial_links() -> list[str]:
    """The links whose scans go down a serial line to a board, in declaration order."""
    return [kind.name for kind in KINDS.values() if kind.serial_line]


def device_names() -> list[str]:
    """The emulated devices the serial links use, sorted."""
    return sorted(kind.device for kind in KINDS.values() if kind.device is not None)


def default_link() -> str:
    """The link a run takes when none is named."""
    return next(kind.name for kind in KINDS.values() if kind.default)


def default_serial_link() -> str:
    """The serial link a board run takes when none is named: the first declared."""
    return serial_links()[0]


def either(names: list[str]) -> str:
    """`names` as a message offers them: ``a or b``, ``a, b or c``."""
    if len(names) <= 1:
        return "".join(names)
    return f"{', '.join(names[:-1])} or {names[-1]}"
