"""Argument types and option groups shared by the commands that run scenarios.

The run options are the run request's table's rows (`add_row`, which notes
in ``args.given`` what the user typed); `request_of` makes the command line's
`RunRequest`. Every type turns bad input into a one-line argparse error
(exit 2); a node's names and parameters are checked by
`harness.commands.node_names`, which the pytest plugin calls too.
"""

from __future__ import annotations

import argparse
import errno
import math
import os
import stat
from collections.abc import Callable, Mapping
from functools import partial
from typing import TYPE_CHECKING, Any

from harness.commands.node_names import checked_node_options
from harness.errors import ConfigError
from harness.links.base import LinkOptions
from harness.links.kinds import default_link, either, link_kind, link_names, serial_links
from harness.run_request import OPTIONS, OptionError, RunRequest, option, values
from harness.run_request.request import check_port as request_check_port
from harness.run_request.table import names as option_names
from harness.safe_text import shown

if TYPE_CHECKING:
    from harness.runner.settings import RunSettings

#: How every command shows a --faults value: a profile name or an inline fault, comma-separated.
FAULTS_METAVAR = option("faults").metavar


def _typed(read: Callable[[object], Any], names: Mapping[str, str]) -> Callable[[str], Any]:
    """`read` (a run_request reader) as an argparse type: its problem worded with `names`
    (after argparse's own "argument --seed:"), one usage line."""

    def parse(text: str) -> Any:
        try:
            return read(text)
        except OptionError as err:
            raise argparse.ArgumentTypeError(err.render(names)) from None

    parse.__name__ = getattr(read, "__name__", "value")  # argparse names the type in messages
    return parse


def positive(kind: str, maximum: float = math.inf) -> Callable[[str], float]:
    """A finite number above zero (and at most `maximum`), named `kind` in the error."""
    return _typed(values.positive(kind, maximum), {kind: kind})


def whole_number(kind: str, low: int, high: int | None = None) -> Callable[[str], int]:
    """A whole number from `low` (to `high`), named `kind` in the error."""
    return _typed(values.whole(kind, low, high), {kind: kind})


def duration(kind: str) -> Callable[[str], float]:
    """Seconds to wait for something: positive, at most a day (the OS's timed waits
    overflow somewhere past 24 days; no wait of the harness needs more than a day)."""
    return positive(kind, values.MAX_WAIT_S)


def row_type(key: str) -> Callable[[str], Any] | None:
    """The argparse type of the table's option `key` (None: its text as is)."""
    row = option(key)
    return None if row.read is None else _typed(row.read, option_names("noun"))


seed = row_type("seed")
domain_id = row_type("domain_id")


def name_list(text: str) -> list[str]:
    """A comma-separated list of names ("a,b"), at least one."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise argparse.ArgumentTypeError("give at least one name")
    return names


def not_empty(text: str) -> str:
    """A value that must not be empty: '' would silently mean "not given" (argparse's
    message names the option)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("must not be empty")
    return text


#: The options that name files or give command lines, each with how its messages name it:
#: `~` and `$VAR` are expanded in them as a shell would (harness.shell_words), since a
#: quoted `--node "python3 ~/lab07/node.py"` reaches us unexpanded.
COMMAND_OPTIONS: Mapping[str, str] = {"node": "--node", "board_command": "--board-command"}
PATH_OPTIONS: Mapping[str, str] = {
    "workspace": "--workspace", "out": "--out", "junit_xml": "--junit-xml",
    "baseline": "--baseline", "record": "--record", "animation": "--animation",
    "grading": "--grading", "gradescope": "--gradescope", "roster": "--roster", "port": "--port",
    "processor": "--processor", "scenarios": "SCENARIO", "dirs": "DIR", "recording": "FILE",
    "world": "WORLD",
}  # fmt: skip
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
        for dest, flag in options.items():
            if hasattr(args, dest):
                setattr(args, dest, each(getattr(args, dest), partial(expand, flag)))


def check_port(option: str, path: str) -> None:
    """A port the user named must be a device (a tty): ConfigError naming `option`."""
    try:
        request_check_port(path)
    except OptionError as err:
        raise err.named({"port": option}) from None


def fault_list(text: str | None) -> list[str] | None:
    """`--faults a,b` as a list; None keeps the scenarios' own."""
    from harness.faults.sensor import split_fault_text

    return split_fault_text(text) if text else None


class _Given(argparse.Action):
    """Stores a value as argparse's store, append and store_true do, and notes in
    ``args.given`` that the user gave it: a file's setting yields only to a typed one."""

    def __init__(self, *args: Any, repeat: bool = False, switch: bool = False, **kw: Any):
        self.repeat, self.switch = repeat, switch
        if switch:
            kw.update(nargs=0, default=kw.get("default", False))
        super().__init__(*args, **kw)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        if self.switch:
            values = True
        elif self.repeat:
            values = [*(getattr(namespace, self.dest, None) or []), values]
        setattr(namespace, self.dest, values)
        namespace.given = frozenset(getattr(namespace, "given", frozenset()) | {self.dest})


def add_row(container: Any, key: str, **changes: Any) -> argparse.Action:
    """The table's option `key` added to a parser or group (its flag, type, default,
    metavar, help); `changes` are a command's own (its help, its default)."""
    row = option(key)
    assert row.cli is not None, f"{key} has no command-line flag"
    kwargs: dict[str, Any] = {"help": row.help, "default": row.default}
    if not row.switch:
        kwargs.update(type=row_type(key), metavar=None if row.choices else row.metavar)
    if row.repeat:
        kwargs["default"] = []
    if row.choices:
        kwargs["choices"] = row.choices
    kwargs.update(changes)
    return container.add_argument(
        row.cli, action=_Given, repeat=row.repeat, switch=row.switch, **kwargs
    )


def add_scenario_overrides(parser: argparse.ArgumentParser) -> None:
    """--seed and --faults: the same scenarios under other fault draws or profiles."""
    add_row(parser, "seed")
    add_row(parser, "faults")


def request_of(args: argparse.Namespace, *, check: bool = True) -> RunRequest:
    """The run request the command line makes (each of the table's options the command
    has), the grading file's values (``args.under``, by key) under what the user typed,
    checked unless `check` is False; ConfigError naming the flags."""
    present = [row for row in OPTIONS if row.cli is not None and hasattr(args, row.dest)]
    typed = getattr(args, "given", frozenset())
    under = getattr(args, "under", {})
    values = {
        row.key: under[row.key]
        if row.key in under and row.dest not in typed
        else getattr(args, row.dest)
        for row in present
    }
    if values.get("launch") is not None:
        values["launch"] = tuple(values["launch"])
    # A problem names the flags: the CLI speaks them (cli.main).
    return RunRequest.of(values, {r.key for r in present if r.dest in typed}, check=check)


def judging_settings(args: argparse.Namespace) -> RunSettings:
    """The run's overrides from --seed, --threshold, --faults, --status-regex and
    --warning-when-clear (the options of add_scenario_overrides and add_judging_options)."""
    return request_of(args, check=False).run_settings()


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
        add_row(
            parser,
            "threshold",
            help=f"the oracle's warning threshold in metres (default: {threshold_default})",
        )
    add_row(parser, "status_regex")
    add_row(
        parser,
        "warning_when_clear",
        help="must the node publish warning False when nothing is within the threshold? "
        "optional (the lab's rule: a Bool only when close passes) or required "
        f"(default: {rule_default})",
    )
    if deadline:
        add_row(
            parser, "scan_timeout", help="seconds to wait for the answers to one scan (default 1)"
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
NODE_ROWS = (
    "node", "package", "executable", "workspace", "params", "threshold_param", "scan_topic",
    "status_topic", "warning_topic", "ready_timeout",
)  # fmt: skip


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
    for key in NODE_ROWS:
        add_row(node, key)
    add_row(node, "domain_id", help=domain_help)
    add_row(node, "ros_network")
    add_row(node, "realtime", help=realtime_help)


def add_link_option(parser: argparse.ArgumentParser) -> None:
    add_row(
        parser,
        "link",
        type=None,  # read when the run is checked: a link declared later is known by then
        default=default_link(),
        help=f"one of {', '.join(link_names())} (default {default_link()})",
    )


def add_device_options(parser: argparse.ArgumentParser) -> None:
    """Where the scans go besides ROS 2: a physical port, or a Python function."""
    serial = parser.add_argument_group(f"serial links ({', '.join(serial_links())})")
    for key in ("port", "board_commands", "lidar_mount"):
        add_row(serial, key)
    functions = [name for name in link_names() if not link_kind(name).runs_node]
    add_row(parser.add_argument_group(f"{either(functions)} link"), "processor")


lidar_mount = row_type("lidar_mount")


def link_options(args: argparse.Namespace) -> LinkOptions:
    """Link settings from the command line, topics and parameters checked
    (`checked_node_options`); the runner fills in the threshold."""
    return checked_node_options(unchecked_link_options(args))


def unchecked_link_options(args: argparse.Namespace) -> LinkOptions:
    """Link settings from the command line as given (`link_options` checks them)."""
    return request_of(args, check=False).link_options()


def check_link_options(args: argparse.Namespace) -> LinkOptions:
    """The link's options, checked once by the run request (options the chosen link
    would silently ignore are mistakes), each board command found, and topics and
    parameters that work (`checked_node_options`)."""
    request = request_of(args)
    if request.board_commands:
        from harness.links.board_session import check_board_commands

        check_board_commands(request.board_commands)  # each program must exist: exit 2 now
    return checked_node_options(request.link_options())


def check_status_regex(args: argparse.Namespace) -> None:
    """A bad regex is a usage error now, not a failure on every tick."""
    pattern = request_of(args, check=False).status_regex
    if pattern:
        from harness.judge.status import parse_status

        parse_status("", pattern)


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
