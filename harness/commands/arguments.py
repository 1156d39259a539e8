"""Argument types and option groups shared by the commands that run scenarios.

Every type turns bad input into a one-line argparse error (exit 2). The
checks of the names and parameters a node gets (a topic used twice, a
parameter that would set the threshold behind the oracle's back) are
`harness.commands.node_names`, which the pytest plugin calls too; which
link takes which option comes from the link table (harness.links.kinds).
"""

from __future__ import annotations

import argparse
import errno
import math
import os
import stat
from collections.abc import Callable, Mapping
from functools import partial
from typing import TYPE_CHECKING

from harness.commands.node_names import checked_node_options
from harness.errors import ConfigError
from harness.lidar.mount import LidarMount, parse_mount
from harness.links.base import LinkOptions
from harness.links.kinds import default_link, either, link_kind, link_names, serial_links
from harness.ros.names import (
    InvalidName,
    check_parameter_rule,
)
from harness.safe_text import shown

if TYPE_CHECKING:
    from harness.runner.settings import RunSettings

NODE_OPTIONS = ("node", "package", "executable", "workspace")
MAX_WAIT_S = 86400.0
#: How every command shows a --faults value: a profile name or an inline fault, comma-separated.
FAULTS_METAVAR = "FAULT[,FAULT]"


def positive(kind: str, maximum: float = math.inf) -> Callable[[str], float]:
    """A finite number above zero (and at most `maximum`), named `kind` in the error."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{kind} must be a number, got {text!r}") from None
        if not math.isfinite(value) or value <= 0:
            raise argparse.ArgumentTypeError(f"{kind} must be a positive number, got {text!r}")
        if value > maximum:
            raise argparse.ArgumentTypeError(f"{kind} must be at most {maximum:g}, got {text!r}")
        return value

    return parse


def whole_number(kind: str, low: int, high: int | None = None) -> Callable[[str], int]:
    """A whole number from `low` (to `high`), named `kind` in the error."""
    bounds = f">= {low}" if high is None else f"{low}..{high}"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(
                f"{kind} must be a whole number {bounds}, got {text[:40]!r}"
            )
        return value

    return parse


def duration(kind: str) -> Callable[[str], float]:
    """Seconds to wait for something: positive, at most a day (the OS's timed waits
    overflow somewhere past 24 days; no wait of the harness needs more than a day)."""
    return positive(kind, MAX_WAIT_S)


def seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"seed must be a whole number, got {text!r}") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"seed must be in 0..2**32-1, got {text!r}")
    return value


domain_id = whole_number("domain id", 0, 232)


def param(text: str) -> str:
    """NAME:=VALUE that ROS 2 itself can parse (harness.ros.names has the rules).

    A rule rcl cannot parse would stop the node before it starts; better a
    usage error now than a failed run.
    """
    try:
        return check_parameter_rule(text)
    except InvalidName as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def name_list(text: str) -> list[str]:
    """A comma-separated list of names ("a,b"), at least one."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise argparse.ArgumentTypeError("give at least one name")
    return names


def given(option: str) -> Callable[[str], str]:
    """A value that must not be empty: '' would silently mean "not given"."""

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError("must not be empty")
        return text

    return parse


#: The options that name files or give command lines, each with how its messages name it:
#: `~` and `$VAR` are expanded in them as a shell would (harness.shell_words), since a
#: quoted `--node "python3 ~/lab07/node.py"` reaches us unexpanded.
COMMAND_OPTIONS: Mapping[str, str] = {"node": "--node", "board_command": "--board-command"}
PATH_OPTIONS: Mapping[str, str] = {
    "workspace": "--workspace",
    "out": "--out",
    "junit_xml": "--junit-xml",
    "baseline": "--baseline",
    "record": "--record",
    "animation": "--animation",
    "grading": "--grading",
    "gradescope": "--gradescope",
    "roster": "--roster",
    "port": "--port",
    "processor": "--processor",
    "scenarios": "SCENARIO",
    "dirs": "DIR",
    "recording": "FILE",
    "world": "WORLD",
}
#: Paths in a comma-separated list: each item expanded (`~` starts each one).
PATH_LIST_OPTIONS: Mapping[str, str] = {"scenario": "--scenario"}  # names or scenario files


def expanded(option: str, value: str, *, command: bool = False) -> str:
    """`value` of `option` with `~` and `$VAR` expanded (a command line's words, or a
    path); ConfigError naming the option for an unset variable or what only a shell does,
    and for a path that expands to nothing."""
    from harness.shell_words import NotExpanded, expand_command, expand_path

    try:
        result = (expand_command if command else expand_path)(value)
    except NotExpanded as err:
        raise ConfigError(f"{option} {shown(value, quoted=True)}: {err}") from None
    if not result.strip() and value.strip():
        raise ConfigError(f"{option} {shown(value, quoted=True)}: expands to nothing")
    return result


def expand_arguments(args: argparse.Namespace) -> None:
    """Every file and command option of `args` expanded in place (`expanded`), as a shell
    would have expanded it unquoted: the one place the command line's are."""

    def each(value: object, expand: Callable[[str], str]) -> object:
        if isinstance(value, list):  # repeated, or a list of names
            return [each(item, expand) for item in value]
        return expand(value) if isinstance(value, str) else value

    expanders: list[tuple[Mapping[str, str], Callable[[str, str], str]]] = [
        (COMMAND_OPTIONS, lambda option, text: expanded(option, text, command=True)),
        (PATH_OPTIONS, expanded),
        (
            PATH_LIST_OPTIONS,
            lambda option, text: ",".join(expanded(option, i) for i in text.split(",")),
        ),
    ]
    for options, expand in expanders:
        for dest, option in options.items():
            if hasattr(args, dest):
                setattr(args, dest, each(getattr(args, dest), partial(expand, option)))


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
    from harness.faults.sensor import split_fault_text

    return split_fault_text(text) if text else None


def add_scenario_overrides(parser: argparse.ArgumentParser) -> None:
    """--seed and --faults: the same scenarios under other fault draws or profiles."""
    parser.add_argument("--seed", type=seed, help="override the scenarios' seed")
    parser.add_argument(
        "--faults",
        metavar=FAULTS_METAVAR,
        help="fault profiles or inline faults such as drop(rate=0.1), replacing the "
        "scenarios' own (see docs/faults.md)",
    )


WARNING_RULES = ("optional", "required")


def warning_rule(text: str) -> str:
    """--warning-when-clear's value (for option parsers without `choices`)."""
    if text not in WARNING_RULES:
        raise argparse.ArgumentTypeError(f"give optional or required, got {text[:40]!r}")
    return text


def judging_settings(args: argparse.Namespace) -> RunSettings:
    """The run's overrides from --seed, --threshold, --faults, --status-regex and
    --warning-when-clear (the options of add_scenario_overrides and add_judging_options)."""
    from harness.runner.settings import RunSettings

    return RunSettings(
        seed=args.seed,
        threshold=args.threshold,
        faults=fault_list(args.faults),
        status_pattern=args.status_regex,
        warning_when_clear=args.warning_when_clear,
    )


def add_judging_options(
    parser: argparse.ArgumentParser,
    *,
    deadline: bool = True,
    threshold: bool = True,
    threshold_default: str = "the scenario's",
    rule_default: str = "the scenario's, optional in every shipped one",
) -> None:
    """How answers are judged and waited for: threshold (unless a command has its own),
    status regex, the warning rule, and (lockstep commands, `deadline`) the per-scan
    timeout. `threshold_default` and `rule_default` say where the defaults come from
    (a replay has no scenario)."""
    if threshold:
        parser.add_argument(
            "--threshold",
            type=positive("threshold"),
            metavar="M",
            help=f"the oracle's warning threshold in metres (default: {threshold_default})",
        )
    parser.add_argument(
        "--status-regex",
        metavar="REGEX",
        help="parse the status with this regex (named groups distance, angle)",
    )
    parser.add_argument(
        "--warning-when-clear",
        choices=WARNING_RULES,
        help="must the node publish warning False when nothing is within the threshold? "
        "optional (the lab's rule: a Bool only when close passes) or required "
        f"(default: {rule_default})",
    )
    if not deadline:
        return
    parser.add_argument(
        "--timeout",
        type=duration("timeout"),
        default=1.0,
        metavar="S",
        help="seconds to wait for the answers to one scan (default 1)",
    )


#: harness.ros.domain's FIRST_ID..LAST_ID (not imported: building the parser stays light).
DOMAIN_HELP = (
    "ROS_DOMAIN_ID (default: a free one in 1..101, reserved for each scenario; with --port, "
    "the board's: the shell's ROS_DOMAIN_ID, else 0); an id is refused while another "
    "fossbot-hil run on this machine holds it"
)
REALTIME_HELP = (
    "send each scan at its time, at the sensor's rate, its answers due before the next "
    "(default: lockstep, the next scan once the node answered)"
)


def add_node_options(
    parser: argparse.ArgumentParser,
    title: str = "node under test (ros2 link; default: the reference node)",
    *,
    domain_help: str = DOMAIN_HELP,
    realtime_help: str = REALTIME_HELP,
) -> None:
    """The node under test and its ROS graph (ros2 link and virtual boards).

    A command whose --domain-id or --realtime works otherwise says so in
    `domain_help` or `realtime_help` (argparse.SUPPRESS: refused, so not shown).
    """
    node = parser.add_argument_group(title)
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
        help="node parameter that receives the threshold (default threshold; '' for none; "
        "a --param of that name is refused: use --threshold)",
    )
    topic_help = "; relative names resolve to /NAME, ~ and {} names are refused"
    node.add_argument(
        "--scan-topic",
        default="/scan",
        metavar="T",
        help="LaserScan topic the node reads (default /scan" + topic_help + ")",
    )
    node.add_argument(
        "--status-topic",
        default="/lidar_status",
        metavar="T",
        help="String topic the node answers on (default /lidar_status)",
    )
    node.add_argument(
        "--warning-topic",
        default="/obstacle_warning",
        metavar="T",
        help="Bool warning topic (default /obstacle_warning); the three topics must differ",
    )
    node.add_argument(
        "--ready-timeout",
        type=duration("ready timeout"),
        default=20.0,
        metavar="S",
        help="seconds for the node to come up (default 20)",
    )
    node.add_argument(
        "--domain-id",
        type=domain_id,
        metavar="N",
        help=domain_help,
    )
    node.add_argument(
        "--ros-network",
        action="store_true",
        help="discover beyond localhost (to watch a board on the network)",
    )
    node.add_argument(
        "--realtime",
        action="store_true",
        help=realtime_help,
    )


def add_link_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--link",
        default=default_link(),
        help=f"one of {', '.join(link_names())} (default {default_link()})",
    )


def add_device_options(parser: argparse.ArgumentParser) -> None:
    """Where the scans go besides ROS 2: a physical port, or a Python function."""
    serial = parser.add_argument_group(f"serial links ({', '.join(serial_links())})")
    serial.add_argument(
        "--port",
        metavar="DEV",
        help="drive a physical board through this USB-UART, in real time "
        "(default: a virtual board on a pty)",
    )
    serial.add_argument(
        "--board-command",
        action="append",
        type=given("--board-command"),
        default=[],
        metavar="CMD",
        help="virtual board: run the board's own software instead of the bundled driver, "
        "{port} replaced by the emulated device's path (repeatable; started before the "
        "first scenario with the run's ROS environment and working modem lines, stopped "
        "after the last; the device then runs in real time; see docs/hil.md)",
    )
    serial.add_argument(
        "--lidar-mount",
        type=lidar_mount,
        metavar="MOUNT",
        help="how the device sits on the robot: model (default: what the robot model says; "
        "the FOSSBot v2's A1 has its zero to the right), forward (zero straight ahead), or "
        "DEG[,mirrored] (the device's zero, degrees counter-clockwise from forward)",
    )
    functions = [name for name in link_names() if not link_kind(name).runs_node]
    inprocess = parser.add_argument_group(f"{either(functions)} link")
    inprocess.add_argument(
        "--processor",
        metavar="MODULE:FUNCTION",
        help="fn(scan, threshold) -> (status, warning) instead of the reference",
    )


def lidar_mount(text: str) -> LidarMount | None:
    """--lidar-mount's value (None: the robot model's)."""
    try:
        return parse_mount(text)
    except ConfigError as err:
        raise argparse.ArgumentTypeError(str(err).removeprefix("--lidar-mount ")) from None


def link_options(args: argparse.Namespace) -> LinkOptions:
    """Link settings from the command line (the runner fills in the threshold), checked.

    ConfigError names the option when a topic or parameter cannot work
    (`checked_node_options`); topics come back fully qualified.
    """
    return checked_node_options(unchecked_link_options(args))


def unchecked_link_options(args: argparse.Namespace) -> LinkOptions:
    """Link settings from the command line as given (`link_options` checks them)."""
    return LinkOptions(
        scan_timeout=getattr(args, "timeout", LinkOptions.scan_timeout),
        ready_timeout=args.ready_timeout,
        processor=getattr(args, "processor", None),
        node=args.node,
        package=args.package,
        executable=args.executable,
        workspace=args.workspace,
        launch=tuple(args.launch) if getattr(args, "launch", None) else None,
        params=tuple(args.param),
        threshold_param=args.threshold_param or None,
        scan_topic=args.scan_topic,
        status_topic=args.status_topic,
        warning_topic=args.warning_topic,
        domain_id=args.domain_id,
        ros_network=args.ros_network,
        realtime=args.realtime,
        port=getattr(args, "port", None),
        board_commands=tuple(getattr(args, "board_command", ()) or ()),
        lidar_mount=getattr(args, "lidar_mount", None),
    )


def check_link_options(args: argparse.Namespace) -> LinkOptions:
    """The link's options, checked: ones the chosen link would silently ignore are
    mistakes, and topics and parameters must work (`link_options`)."""
    port = getattr(args, "port", None)
    processor = getattr(args, "processor", None)
    kind = link_kind(args.link)
    serial = f"--link {either(serial_links())}"
    if port is not None:
        check_port("--port", port)
    if port and not kind.serial_line:
        raise ConfigError(f"--port needs {serial}, not {args.link}")
    board = getattr(args, "board_command", None)
    if board and not kind.serial_line:
        raise ConfigError(f"--board-command needs {serial}, not {args.link}")
    if board and port:
        raise ConfigError(
            "--board-command runs the board's software on the virtual board; with --port the "
            "physical board runs its own"
        )
    if board:
        from harness.links.board_session import check_board_commands

        check_board_commands(tuple(board))  # each program must exist: exit 2 now, not later
    if getattr(args, "lidar_mount", None) is not None and not kind.serial_line:
        raise ConfigError(
            f"--lidar-mount needs {serial} (the {args.link} link sends the scan frame itself)"
        )
    functions = [name for name in link_names() if not link_kind(name).runs_node]
    if processor and kind.runs_node:
        raise ConfigError(
            f"--processor needs --link {either(functions)} (the {args.link} link runs a node)"
        )
    if not kind.runs_node:
        given = [f"--{name}" for name in NODE_OPTIONS if getattr(args, name)] + (
            ["--param"] if args.param else []
        )
        if given:
            raise ConfigError(f"{given[0]} needs a link that runs a node, not --link {args.link}")
    return link_options(args)


def check_status_regex(args: argparse.Namespace) -> None:
    """A bad regex is a usage error now, not a failure on every tick."""
    if args.status_regex:
        from harness.judge.status import parse_status

        parse_status("", args.status_regex)


def check_output_file(option: str, path: str | None) -> None:
    """A file the command will write (--junit-xml, --record): not a folder, in one that exists.

    Checked before anything runs, so a typo costs nothing; an existing
    regular file is overwritten (atomically), anything else is refused.
    """
    if path is None:
        return
    text = path if path.isprintable() else repr(path)
    if not path.strip():
        raise ConfigError(f"{option} must not be empty")
    if path.endswith(("/", os.sep)):
        raise ConfigError(f"{option} {text}: names a folder, not a file")
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except (OSError, ValueError) as err:
        if getattr(err, "errno", None) == errno.ENOTDIR:
            raise ConfigError(f"{option} {text}: a part of this path is a file") from None
        raise ConfigError(f"{option} {text}: {getattr(err, 'strerror', None) or err}") from None
    if mode is not None and stat.S_ISDIR(mode):
        raise ConfigError(f"{option} {text}: a folder, not a file")
    if mode is not None and not stat.S_ISREG(mode):
        raise ConfigError(f"{option} {text}: exists and is not a regular file")
    if not os.path.isdir(os.path.dirname(os.path.abspath(path))):
        raise ConfigError(f"{option} {text}: its folder does not exist")
