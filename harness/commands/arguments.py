"""Argument types and option groups shared by the commands that run scenarios.

Every type turns bad input into a one-line argparse error (exit 2).
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import stat
from collections.abc import Callable

from harness.errors import ConfigError
from harness.links.base import LinkOptions, known_links

DEFAULT_LINK = "ros2"
SERIAL_LINKS = ("rplidar", "ldlidar")
NODE_OPTIONS = ("node", "package", "executable", "workspace")


def positive(kind: str) -> Callable[[str], float]:
    """A finite number above zero, named `kind` in the error."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{kind} must be a number, got {text!r}") from None
        if not math.isfinite(value) or value <= 0:
            raise argparse.ArgumentTypeError(f"{kind} must be a positive number, got {text!r}")
        return value

    return parse


def seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"seed must be a whole number, got {text!r}") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"seed must be in 0..2**32-1, got {text!r}")
    return value


def domain_id(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 232:
        raise argparse.ArgumentTypeError(f"domain id must be a whole number 0..232, got {text!r}")
    return value


def param(text: str) -> str:
    """NAME:=VALUE, and (where rclpy is installed) one ROS 2 itself can parse.

    A rule rcl cannot parse would stop the node before it starts; better a
    usage error now than a failed run.
    """
    name, sep, value = text.partition(":=")
    if not sep or not name or not value or any(c.isspace() for c in name):
        raise argparse.ArgumentTypeError(f"expected NAME:=VALUE, got {text!r}")
    if importlib.util.find_spec("rclpy") is not None:
        from rclpy.utilities import remove_ros_args

        try:
            remove_ros_args(["fossbot-hil", "--ros-args", "-p", text])
        except Exception as err:  # noqa: BLE001 - rclpy's RCLInvalidROSArgsError and kin
            reason = str(err).split("Error: ", 1)[-1].split(", at ", 1)[0]
            raise argparse.ArgumentTypeError(
                f"ROS 2 cannot parse {text!r}: {' '.join(reason.split())[:150]}"
            ) from None
    return text


def given(option: str) -> Callable[[str], str]:
    """A value that must not be empty: '' would silently mean "not given"."""

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError("must not be empty")
        return text

    return parse


def check_port(option: str, path: str) -> None:
    """A port the user named must be a device (a tty), not a file or a folder or nothing.

    Checked before the port is locked or opened, so a typo leaves nothing behind.
    """
    if not path.strip():
        raise ConfigError(f"{option} must not be empty")
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise ConfigError(f"{option} {path}: no such device") from None
    except (OSError, ValueError) as err:
        raise ConfigError(f"{option} {path}: {getattr(err, 'strerror', None) or err}") from None
    if stat.S_ISDIR(mode):
        raise ConfigError(f"{option} {path}: a folder, not a serial port")
    if not stat.S_ISCHR(mode):
        raise ConfigError(f"{option} {path}: not a serial port (not a character device)")


def fault_list(text: str | None) -> list[str] | None:
    """`--faults a,b` as a list; None keeps the scenarios' own."""
    from harness.faults import split_fault_text

    return split_fault_text(text) if text else None


def add_scenario_overrides(parser: argparse.ArgumentParser) -> None:
    """--seed and --faults: the same scenarios under other fault draws or profiles."""
    parser.add_argument("--seed", type=seed, help="override the scenarios' seed")
    parser.add_argument(
        "--faults",
        metavar="NAME[,NAME]",
        help="fault profiles or inline faults such as drop(rate=0.1), replacing the "
        "scenarios' own (see docs/faults.md)",
    )


def add_judging_options(parser: argparse.ArgumentParser) -> None:
    """How answers are judged and waited for: threshold, status regex, timeout."""
    parser.add_argument(
        "--threshold",
        type=positive("threshold"),
        metavar="M",
        help="the oracle's warning threshold in metres (default: the scenario's)",
    )
    parser.add_argument(
        "--status-regex",
        metavar="REGEX",
        help="parse the status with this regex (named groups distance, angle)",
    )
    parser.add_argument(
        "--timeout",
        type=positive("timeout"),
        default=1.0,
        metavar="S",
        help="seconds to wait for the answers to one scan (default 1)",
    )


def add_node_options(parser: argparse.ArgumentParser) -> None:
    """The node under test and its ROS graph (ros2 link and virtual boards)."""
    node = parser.add_argument_group("node under test (ros2 link; default: the reference node)")
    node.add_argument(
        "--node",
        type=given("--node"),
        metavar="CMD",
        help='shell command, e.g. "python3 my_node.py"',
    )
    node.add_argument(
        "--package", type=given("--package"), metavar="PKG", help="package in a colcon workspace"
    )
    node.add_argument(
        "--executable", type=given("--executable"), metavar="EXE", help="executable of --package"
    )
    node.add_argument(
        "--workspace",
        type=given("--workspace"),
        metavar="DIR",
        help="colcon workspace (has install/)",
    )
    node.add_argument(
        "--param",
        action="append",
        type=param,
        default=[],
        metavar="NAME:=VALUE",
        help="node parameter, passed verbatim (repeatable)",
    )
    node.add_argument(
        "--threshold-param",
        default="threshold",
        metavar="NAME",
        help="node parameter that receives the threshold ('' for none)",
    )
    node.add_argument("--scan-topic", default="/scan", metavar="T")
    node.add_argument("--status-topic", default="/lidar_status", metavar="T")
    node.add_argument("--warning-topic", default="/obstacle_warning", metavar="T")
    node.add_argument(
        "--ready-timeout",
        type=positive("ready timeout"),
        default=20.0,
        metavar="S",
        help="seconds for the node to come up (default 20)",
    )
    node.add_argument(
        "--domain-id",
        type=domain_id,
        metavar="N",
        help="ROS_DOMAIN_ID (default: a free one reserved for the run)",
    )
    node.add_argument(
        "--ros-network",
        action="store_true",
        help="discover beyond localhost (to watch a board on the network)",
    )
    node.add_argument(
        "--realtime",
        action="store_true",
        help="send scans at the sensor's rate instead of lockstep",
    )


def add_link_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--link", default=DEFAULT_LINK, help=f"one of {', '.join(known_links())}")


def add_device_options(parser: argparse.ArgumentParser) -> None:
    """Where the scans go besides ROS 2: a physical port, or a Python function."""
    serial = parser.add_argument_group("serial links (rplidar, ldlidar)")
    serial.add_argument(
        "--port",
        metavar="DEV",
        help="drive a physical board through this USB-UART, in real time "
        "(default: a virtual board on a pty)",
    )
    inprocess = parser.add_argument_group("inprocess link")
    inprocess.add_argument(
        "--processor",
        metavar="MODULE:FUNCTION",
        help="fn(scan, threshold) -> (status, warning) instead of the reference",
    )


def link_options(args: argparse.Namespace) -> LinkOptions:
    """Link settings from the command line (the runner fills in the threshold)."""
    return LinkOptions(
        scan_timeout=args.timeout,
        ready_timeout=args.ready_timeout,
        processor=getattr(args, "processor", None),
        node=args.node,
        package=args.package,
        executable=args.executable,
        workspace=args.workspace,
        params=tuple(args.param),
        threshold_param=args.threshold_param or None,
        scan_topic=args.scan_topic,
        status_topic=args.status_topic,
        warning_topic=args.warning_topic,
        domain_id=args.domain_id,
        ros_network=args.ros_network,
        realtime=args.realtime,
        port=getattr(args, "port", None),
    )


def check_link_options(args: argparse.Namespace) -> None:
    """Options that the chosen link would silently ignore are mistakes."""
    port = getattr(args, "port", None)
    processor = getattr(args, "processor", None)
    if port is not None:
        check_port("--port", port)
    if port and args.link not in SERIAL_LINKS:
        raise ConfigError(f"--port needs --link rplidar or ldlidar, not {args.link}")
    if processor and args.link != "inprocess":
        raise ConfigError(f"--processor needs --link inprocess (the {args.link} link runs a node)")
    if args.link == "inprocess":
        given = [f"--{name}" for name in NODE_OPTIONS if getattr(args, name)] + (
            ["--param"] if args.param else []
        )
        if given:
            raise ConfigError(f"{given[0]} needs a link that runs a node, not --link inprocess")


def check_status_regex(args: argparse.Namespace) -> None:
    """A bad regex is a usage error now, not a failure on every tick."""
    if args.status_regex:
        from harness.status import parse_status

        parse_status("", args.status_regex)
