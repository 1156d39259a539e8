"""The run options, one row each: the one table the CLI, the plugin and the grading file
are built from (a new option is one row here)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from harness.option_names import Names
from harness.run_request import values
from harness.run_request.values import Reader

WARNING_RULES = ("optional", "required")
DEFAULT_TIMEOUT_S = 1.0
DEFAULT_READY_TIMEOUT_S = 20.0
DEFAULT_PORT_WAIT_S = 300.0  # a whole board run, in real time, may be ahead in the queue


@dataclass(frozen=True)
class RunOption:
    """One run option and how each caller names it (None: that caller has no such option)."""

    key: str  # the RunRequest field
    noun: str  # how a value's problem names it after the caller's prefix ("ready timeout")
    read: Reader | None = None  # text or a typed value -> the value; None: any text as is
    default: Any = None
    cli: str | None = None  # "--ready-timeout"
    metavar: str | None = None
    help: str = ""
    hil: str | None = None  # the plugin's "--hil-<hil>" option ...
    ini: bool = True  # ... and its "hil_<hil>" ini key (False: a machine's, not a project's)
    hil_help: str | None = None  # the plugin's help, where it differs from the CLI's
    hil_metavar: str | None = None  # the plugin's metavar, where it differs from the CLI's
    grading: str | None = None  # the grading file's field
    run: str | None = None  # hil.run's keyword (and HilConfig's ...)
    repeat: bool = False  # given again, adds an item
    switch: bool = False  # a flag without a value
    choices: tuple[str, ...] | None = None
    number: bool = False  # a number: typed callers (hil.run, a YAML file) may not give text

    @property
    def dest(self) -> str:
        """The argparse name of the CLI flag."""
        assert self.cli is not None
        return self.cli.removeprefix("--").replace("-", "_")

    @property
    def hil_flag(self) -> str:
        assert self.hil is not None
        return "--hil-" + self.hil.replace("_", "-")

    @property
    def ini_key(self) -> str:
        assert self.hil is not None
        return "hil_" + self.hil

    def value(self, given: object) -> Any:
        """`given` (text, or already typed) as this option's value; OptionError if not."""
        return given if self.read is None or given is None else self.read(given)


_TOPIC_HELP = "; relative names resolve to /NAME, ~ and {} names are refused"

OPTIONS: tuple[RunOption, ...] = (
    RunOption(
        "link",
        "link",
        values.link,
        cli="--link",
        hil="link",
        hil_metavar="NAME",
        grading="link",
        run="link",
    ),
    RunOption(
        "node",
        "node",
        values.text("node"),
        cli="--node",
        metavar="CMD",
        help='shell command, e.g. "python3 my_node.py"',
        hil="node",
        hil_help='node under test as a shell command, e.g. "python3 my_node.py"',
        run="node",
    ),
    RunOption(
        "package",
        "package",
        values.text("package"),
        cli="--package",
        metavar="PKG",
        help="package in a colcon workspace",
        hil="package",
        hil_help="node under test: a package in a colcon workspace",
        grading="package",
        run="package",
    ),
    RunOption(
        "executable",
        "executable",
        values.text("executable"),
        cli="--executable",
        metavar="EXE",
        help="executable of --package",
        hil="executable",
        hil_help="executable of --hil-package",
        grading="executable",
        run="executable",
    ),
    RunOption(
        "workspace",
        "workspace",
        values.text("workspace"),
        cli="--workspace",
        metavar="DIR",
        help="colcon workspace (has install/)",
        hil="workspace",
        hil_help="colcon workspace of --hil-package (has install/)",
        run="workspace",
    ),
    RunOption(
        "params",
        "param",
        values.parameter,
        default=(),
        cli="--param",
        metavar="NAME:=VALUE",
        help="node parameter, passed verbatim (repeatable)",
        hil="param",
        hil_help="node parameter, passed verbatim (repeatable; ini: hil_param, one per line)",
        run="params",
        repeat=True,
    ),
    RunOption(
        "threshold_param",
        "threshold param",
        default="threshold",
        cli="--threshold-param",
        metavar="NAME",
        help="node parameter that receives the threshold (default threshold; '' for none; "
        "a --param of that name is refused: use --threshold)",
        run="threshold_param",
    ),
    RunOption(
        "scan_topic",
        "scan topic",
        default="/scan",
        cli="--scan-topic",
        metavar="T",
        help="LaserScan topic the node reads (default /scan" + _TOPIC_HELP + ")",
        run="scan_topic",
    ),
    RunOption(
        "status_topic",
        "status topic",
        default="/lidar_status",
        cli="--status-topic",
        metavar="T",
        help="String topic the node answers on (default /lidar_status)",
        run="status_topic",
    ),
    RunOption(
        "warning_topic",
        "warning topic",
        default="/obstacle_warning",
        cli="--warning-topic",
        metavar="T",
        help="Bool warning topic (default /obstacle_warning); the three topics must differ",
        run="warning_topic",
    ),
    RunOption(
        "ready_timeout",
        "ready timeout",
        values.duration("ready_timeout"),
        default=DEFAULT_READY_TIMEOUT_S,
        cli="--ready-timeout",
        metavar="S",
        help=f"seconds for the node to come up (default {DEFAULT_READY_TIMEOUT_S:g})",
        hil="ready_timeout",
        grading="ready_timeout",
        run="ready_timeout",
        number=True,
    ),
    RunOption(
        "domain_id",
        "domain id",
        values.whole("domain_id", 0, 232),
        cli="--domain-id",
        metavar="N",
        hil="domain_id",
        ini=False,
        hil_help="ROS_DOMAIN_ID (default: a free one reserved per run; a board's: 0)",
        run="domain_id",
        number=True,
    ),
    RunOption(
        "ros_network",
        "ros network",
        default=False,
        cli="--ros-network",
        help="discover beyond localhost (to watch a board on the network)",
        run="ros_network",
        switch=True,
    ),
    RunOption("realtime", "realtime", default=False, cli="--realtime", run="realtime", switch=True),
    RunOption(
        "port",
        "port",
        cli="--port",
        metavar="DEV",
        help="drive a physical board through this USB-UART, in real time "
        "(default: a virtual board on a pty)",
        hil="port",
        ini=False,
        hil_help="USB-UART wired to the board's LIDAR input (enables hil tests)",
        run="port",
    ),
    RunOption(
        "board_commands",
        "board command",
        values.text("board_commands"),
        default=(),
        cli="--board-command",
        metavar="CMD",
        help="virtual board: run the board's own software instead of the bundled driver, "
        "{port} replaced by the emulated device's path (repeatable; started before the "
        "first scenario with the run's ROS environment and working modem lines, stopped "
        "after the last; the device then runs in real time; see docs/hil.md)",
        run="board_commands",
        repeat=True,
    ),
    RunOption(
        "lidar_mount",
        "lidar mount",
        values.lidar_mount,
        cli="--lidar-mount",
        metavar="MOUNT",
        help="how the device sits on the robot: model (default: what the robot model says; "
        "the FOSSBot v2's A1 has its zero to the right), forward (zero straight ahead), or "
        "DEG[,mirrored] (the device's zero, degrees counter-clockwise from forward)",
        run="lidar_mount",
    ),
    RunOption(
        "launch",
        "launch",
        cli="--launch",
        metavar="PACKAGE FILE",
        help="start the node under test by `ros2 launch PACKAGE FILE` (needs ros2 with its "
        "launch verb, from a sourced ROS 2; --workspace DIR finds the package), the harness's "
        "parameters passed as the launch arguments the file declares; instead of "
        "--node/--package (see docs/launch_files.md)",
    ),
    RunOption(
        "processor",
        "processor",
        cli="--processor",
        metavar="MODULE:FUNCTION",
        help="fn(scan, threshold) -> (status, warning) instead of the reference",
        run="processor",
    ),
    RunOption(
        "seed",
        "seed",
        values.seed,
        cli="--seed",
        help="override the scenarios' seed",
        hil="seed",
        hil_help="seed for every run (default: each scenario's)",
        hil_metavar="N",
        grading="seed",
        run="seed",
        number=True,
    ),
    RunOption(
        "faults",
        "faults",
        cli="--faults",
        metavar="FAULT[,FAULT]",
        help="fault profiles or inline faults such as drop(rate=0.1), replacing the "
        "scenarios' own (see docs/faults.md)",
        grading="faults",
        run="faults",
    ),
    RunOption(
        "threshold",
        "threshold",
        values.positive("threshold"),
        cli="--threshold",
        metavar="M",
        grading="threshold",
        run="threshold",
        number=True,
    ),
    RunOption(
        "status_regex",
        "status regex",
        cli="--status-regex",
        metavar="REGEX",
        help="parse the status with this regex (named groups distance, angle)",
        grading="status_regex",
        run="status_regex",
    ),
    RunOption(
        "warning_when_clear",
        "warning rule",
        values.choice("warning_when_clear", WARNING_RULES),
        cli="--warning-when-clear",
        hil="warning_when_clear",
        hil_metavar="RULE",
        hil_help="must the node publish warning False when nothing is within the threshold: "
        "optional (the lab's rule) or required (default: each scenario's, optional)",
        grading="warning_when_clear",
        run="warning_when_clear",
        choices=WARNING_RULES,
    ),
    RunOption(
        "scan_timeout",
        "timeout",
        values.duration("scan_timeout"),
        default=DEFAULT_TIMEOUT_S,
        cli="--timeout",
        metavar="S",
        help=f"seconds to wait for the answers to one scan (default {DEFAULT_TIMEOUT_S:g})",
        hil="timeout",
        grading="timeout",
        run="scan_timeout",
        number=True,
    ),
    RunOption(
        "port_wait",
        "port wait",
        values.duration("port_wait"),
        default=DEFAULT_PORT_WAIT_S,
        hil="port_wait",
        hil_help="seconds to wait while another run uses --hil-port "
        f"(default {DEFAULT_PORT_WAIT_S:g})",
        number=True,
    ),
)
_BY_KEY = {row.key: row for row in OPTIONS}


def option(key: str) -> RunOption:
    """The row of `key`."""
    return _BY_KEY[key]


def names(of: str) -> Names:
    """How one caller names the options in messages: "cli" (--seed), "hil" (--hil-seed),
    "noun" (seed: after argparse's own "argument --seed:"), "run" (hil.run's seed=),
    "grading" (the grading file's field)."""
    table: dict[str, str] = {}
    for row in OPTIONS:
        name = (row.hil_flag if row.hil else None) if of == "hil" else getattr(row, of)
        table[row.key] = name if name is not None else row.key
    return table


def reads(keys: Mapping[str, object]) -> dict[str, Any]:
    """Each of `keys`' values read by its row (text or typed in, typed out)."""
    return {key: option(key).value(value) for key, value in keys.items()}
