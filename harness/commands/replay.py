"""`fossbot-hil replay`: judge a node against a recorded scan stream."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from rich.console import Console

from harness.commands.arguments import (
    FAULTS_METAVAR,
    add_device_options,
    add_judging_options,
    add_link_option,
    add_node_options,
    check_link_options,
    check_output_file,
    check_status_regex,
    fault_list,
    not_empty,
    seed,
)
from harness.commands.node_names import topic_option
from harness.errors import ConfigError, Interrupted

if TYPE_CHECKING:  # numpy comes with it: not needed to build the parser
    from harness.faults.link import LinkFaults

NAME = "replay"
HELP = "re-inject a recorded /scan stream (ours or a robot's rosbag2) and judge the node"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "recording", metavar="FILE", help="an MCAP file, a rosbag2 folder or a .db3 file"
    )
    parser.add_argument(
        "--topic",
        metavar="T",
        help="the LaserScan topic to replay (default: /scan, or the only LaserScan topic; "
        "a relative name means /NAME)",
    )
    add_link_option(parser)
    add_judging_options(  # a replay has no scenario: the recording says what it can
        parser,
        threshold_default="the recording's; a robot's rosbag2 has none, so give it",
        rule_default="optional",
    )
    parser.add_argument(
        "--junit-xml", type=not_empty, metavar="FILE", help="write a JUnit XML report"
    )
    parser.add_argument(
        "--faults",
        metavar=FAULTS_METAVAR,
        help="link faults on the replayed scans, e.g. lossy_link,delay(mean=0.05) "
        "(see docs/faults.md); the scans themselves are sent as recorded",
    )
    parser.add_argument(
        "--seed", type=seed, help="seed of the link faults (default: the recording's)"
    )
    parser.add_argument(
        "--record",
        type=not_empty,
        metavar="FILE",
        help="write the replayed run as a new MCAP recording",
    )
    add_node_options(parser)
    add_device_options(parser)


def replay_link_faults(text: str | None) -> LinkFaults:
    """--faults for a replay: link faults only, and no re-timing of recorded scans."""
    from harness.faults.link import NO_LINK_FAULTS
    from harness.faults.sensor import build_profile

    items = fault_list(text)
    if not items:
        return NO_LINK_FAULTS
    try:
        profile = build_profile(items)
    except ConfigError as err:
        raise ConfigError(f"--faults: {err}") from None
    if profile.faults or profile.convention != "rep117":
        raise ConfigError(
            f"--faults: {', '.join(f.kind for f in profile.faults) or 'convention'}: a replay "
            "sends the recorded scans as they are; only link faults apply"
        )
    if profile.link.get("rate_drift") is not None:
        raise ConfigError("--faults: rate_drift: a replay keeps the recorded scan times")
    return profile.link


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.record import read_scans
    from harness.report.terminal import print_results
    from harness.runner.replay import replay

    options = check_link_options(args)
    check_status_regex(args)
    check_output_file("--junit-xml", args.junit_xml)
    check_output_file("--record", args.record)
    topic = None if args.topic is None else topic_option("--topic ", args.topic)
    link_faults = replay_link_faults(args.faults)
    recording = read_scans(args.recording, topic)
    try:
        result = replay(
            recording,
            args.link,
            options,
            threshold=args.threshold,
            status_pattern=args.status_regex,
            warning_when_clear=args.warning_when_clear,
            link_faults=link_faults,
            seed=args.seed,
        )
    except Interrupted as stop:  # what was judged before Ctrl-C or SIGTERM, then stop
        print_results(console, stop.results)
        raise Interrupted(stop.signum, stop.results, "the replay was judged in part") from None
    print_results(console, [result])
    if args.record:
        from harness.record import write_recording

        write_recording(args.record, result)
    if args.junit_xml:
        from harness.report.junit import write_junit

        write_junit(args.junit_xml, [result])
    return 0 if result.ok else 1
