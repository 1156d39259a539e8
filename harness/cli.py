"""`fossbot-hil`: list scenarios and run them against a node or a board.

Exit codes: 0 every expectation held, 1 some failed, 2 usage or
configuration error (one line on stderr naming the file or field).
"""

from __future__ import annotations

import argparse
import math
import signal
import sys
from collections.abc import Sequence
from pathlib import Path

from rich.console import Console

from harness import __version__
from harness.errors import ConfigError, HarnessError
from harness.links.base import LinkOptions, known_links
from harness.scenario import Scenario, resolve_scenario, shipped_scenarios
from harness.trace import RunResult

DEFAULT_LINK = "ros2"
EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130


class _Parser(argparse.ArgumentParser):
    """argparse, but usage errors are one line and exit 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise ConfigError(f"{message} (see '{self.prog} --help')")


def _positive(kind: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{kind} must be a number, got {text!r}") from None
        if not math.isfinite(value) or value <= 0:
            raise argparse.ArgumentTypeError(f"{kind} must be a positive number, got {text!r}")
        return value

    return parse


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"seed must be a whole number, got {text!r}") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"seed must be in 0..2**32-1, got {text!r}")
    return value


def _domain_id(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 232:
        raise argparse.ArgumentTypeError(f"domain id must be a whole number 0..232, got {text!r}")
    return value


def _param(text: str) -> str:
    name, sep, value = text.partition(":=")
    if not sep or not name or not value or any(c.isspace() for c in name):
        raise argparse.ArgumentTypeError(f"expected NAME:=VALUE, got {text!r}")
    return text


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="fossbot-hil", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    commands.add_parser("list", help="list the shipped scenarios")
    commands.add_parser("ports", help="list serial adapters (for --port)")

    emulate = commands.add_parser(
        "emulate", help="serve a scenario's scans as a LIDAR device on a serial port"
    )
    emulate.add_argument("device", choices=["rplidar", "ldlidar"])
    emulate.add_argument(
        "--scenario", required=True, metavar="NAME", help="shipped scenario name or scenario file"
    )
    emulate.add_argument(
        "--port",
        metavar="DEV",
        help="serial port to serve on (default: a new pty; its path is printed)",
    )
    emulate.add_argument("--seed", type=_seed, help="override the scenario's seed")
    emulate.add_argument("--faults", metavar="NAME[,NAME]", help="fault profiles to apply")

    run = commands.add_parser("run", help="run scenarios and judge the node's answers")
    run.add_argument(
        "scenarios",
        nargs="*",
        metavar="SCENARIO",
        help="shipped scenario name or path to a scenario file (default: all shipped)",
    )
    run.add_argument("--link", default=DEFAULT_LINK, help=f"one of {', '.join(known_links())}")
    run.add_argument("--seed", type=_seed, help="override the scenarios' seed")
    run.add_argument(
        "--threshold",
        type=_positive("threshold"),
        metavar="M",
        help="the oracle's warning threshold in metres (default: the scenario's)",
    )
    run.add_argument(
        "--faults",
        metavar="NAME[,NAME]",
        help="fault profiles replacing the scenarios' own (see docs/faults.md)",
    )
    run.add_argument(
        "--status-regex",
        metavar="REGEX",
        help="parse the status with this regex (named groups distance, angle)",
    )
    run.add_argument(
        "--timeout",
        type=_positive("timeout"),
        default=1.0,
        metavar="S",
        help="seconds to wait for the answers to one scan (default 1)",
    )
    run.add_argument("--gui", action="store_true", help="open the PyBullet viewer")

    run.add_argument("--junit-xml", metavar="FILE", help="write a JUnit XML report")

    node = run.add_argument_group("node under test (ros2 link; default: the reference node)")
    node.add_argument("--node", metavar="CMD", help='shell command, e.g. "python3 my_node.py"')
    node.add_argument("--package", metavar="PKG", help="package in a colcon workspace")
    node.add_argument("--executable", metavar="EXE", help="executable of --package")
    node.add_argument("--workspace", metavar="DIR", help="colcon workspace (has install/)")
    node.add_argument(
        "--param",
        action="append",
        type=_param,
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
        type=_positive("ready timeout"),
        default=20.0,
        metavar="S",
        help="seconds for the node to come up (default 20)",
    )
    node.add_argument(
        "--domain-id",
        type=_domain_id,
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

    serial = run.add_argument_group("serial links (rplidar, ldlidar)")
    serial.add_argument(
        "--port",
        metavar="DEV",
        help="drive a physical board through this USB-UART, in real time "
        "(default: a virtual board on a pty)",
    )

    inprocess = run.add_argument_group("inprocess link")
    inprocess.add_argument(
        "--processor",
        metavar="MODULE:FUNCTION",
        help="fn(scan, threshold) -> (status, warning) instead of the reference",
    )
    return parser


def _print_error(message: str) -> None:
    print(f"fossbot-hil: error: {message}", file=sys.stderr)


def _selected(names: Sequence[str]) -> list[Scenario]:
    return [resolve_scenario(n) for n in names] if names else shipped_scenarios()


def _link_options(args: argparse.Namespace) -> LinkOptions:
    """Link settings from the command line (the runner fills in the threshold)."""
    return LinkOptions(
        scan_timeout=args.timeout,
        ready_timeout=args.ready_timeout,
        processor=args.processor,
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
        port=args.port,
    )


def _fault_list(text: str | None) -> list[str] | None:
    return [f.strip() for f in text.split(",") if f.strip()] if text else None


def _run_one(scenario: Scenario, args: argparse.Namespace) -> RunResult:
    from harness.runner import RunSettings, run

    faults = _fault_list(args.faults)
    settings = RunSettings(
        seed=args.seed,
        threshold=args.threshold,
        faults=faults,
        status_pattern=args.status_regex,
        gui=args.gui,
    )
    return run(scenario, args.link, _link_options(args), settings)


def _run_all(scenarios: Sequence[Scenario], args: argparse.Namespace) -> list[RunResult]:
    """Run each scenario; once the node fails to come up, the rest are not tried."""
    results: list[RunResult] = []
    failed_start: str | None = None
    for scenario in scenarios:
        if failed_start is not None:
            reason = f"not run: the node did not start in {failed_start}"
            skipped = RunResult(scenario.name, args.link, 0, 0.0, "", error=reason, not_run=True)
            results.append(skipped)
            continue
        result = _run_one(scenario, args)
        results.append(result)
        if result.not_started:
            failed_start = scenario.name
    return results


NODE_OPTIONS = ("node", "package", "executable", "workspace")


def _check_link_options(args: argparse.Namespace) -> None:
    """Options that the chosen link would silently ignore are mistakes."""
    if args.port and args.link not in ("rplidar", "ldlidar"):
        raise ConfigError(f"--port needs --link rplidar or ldlidar, not {args.link}")
    if args.processor and args.link != "inprocess":
        raise ConfigError(f"--processor needs --link inprocess (the {args.link} link runs a node)")
    if args.link == "inprocess":
        given = [f"--{name}" for name in NODE_OPTIONS if getattr(args, name)] + (
            ["--param"] if args.param else []
        )
        if given:
            raise ConfigError(f"{given[0]} needs a link that runs a node, not --link inprocess")


def cmd_list(args: argparse.Namespace, console: Console) -> int:
    from harness.report.terminal import scenario_table

    console.print(scenario_table(shipped_scenarios()))
    return EXIT_OK


def cmd_run(args: argparse.Namespace, console: Console) -> int:
    from harness.report.terminal import print_results

    _check_link_options(args)
    scenarios = _selected(args.scenarios)  # all resolved before anything runs
    if args.junit_xml and not Path(args.junit_xml).resolve().parent.is_dir():
        raise ConfigError(f"--junit-xml {args.junit_xml}: its folder does not exist")
    if args.status_regex:
        from harness.status import parse_status

        parse_status("", args.status_regex)  # a bad regex is a usage error, now
    results = _run_all(scenarios, args)
    print_results(console, results)
    if args.junit_xml:
        from harness.report.junit import write_junit

        try:
            write_junit(args.junit_xml, results)
        except OSError as err:
            raise ConfigError(f"--junit-xml {args.junit_xml}: {err.strerror or err}") from None
    return EXIT_OK if all(r.ok for r in results) else EXIT_FAILED


def cmd_ports(args: argparse.Namespace, console: Console) -> int:
    from harness.serial_line.ports import list_serial_ports

    ports = list_serial_ports()
    for port in ports:
        console.print(port.line(), markup=False)
    if not ports:
        console.print("no serial adapters found (plug in the USB-UART, then try again)")
    return EXIT_OK


def cmd_emulate(args: argparse.Namespace, console: Console) -> int:
    from harness.devices.profiles import profile
    from harness.emulate import emulate
    from harness.runner import RunSettings

    scenario = resolve_scenario(args.scenario)
    settings = RunSettings(seed=args.seed, faults=_fault_list(args.faults))
    summary = emulate(
        profile(args.device),
        scenario,
        port=args.port,
        settings=settings,
        announce=lambda line: print(line, flush=True),
    )
    rate = summary.mean_rate_error_pct
    console.print(
        f"served {summary.revolutions_streamed} of {summary.revolutions} revolutions "
        f"({summary.bytes_written} bytes"
        + (f", line rate error {rate:+.2f} %" if rate is not None else "")
        + ")",
        markup=False,
    )
    return EXIT_OK


COMMANDS = {"list": cmd_list, "run": cmd_run, "ports": cmd_ports, "emulate": cmd_emulate}


def _interrupt_on_sigterm() -> None:
    """SIGTERM ends a run like Ctrl-C does: links close, nodes are stopped and reaped."""

    def handler(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, handler)


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; return its exit code (for tests and embedding)."""
    console = Console(highlight=False)
    if not console.is_terminal:
        console = Console(highlight=False, width=200)  # files and pipes: no wrapping
    try:
        args = build_parser().parse_args(argv)
        if args.command is None:
            build_parser().print_help()
            return EXIT_USAGE
        return COMMANDS[args.command](args, console)
    except ConfigError as err:
        _print_error(str(err))
        return EXIT_USAGE
    except KeyboardInterrupt:
        _print_error("interrupted")
        return EXIT_INTERRUPTED
    except HarnessError as err:
        _print_error(str(err))
        return EXIT_FAILED


def entry() -> None:
    """The `fossbot-hil` console script."""
    _interrupt_on_sigterm()
    sys.exit(main())


if __name__ == "__main__":
    entry()
