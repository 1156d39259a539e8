"""`fossbot-hil replay`: judge a node against a recorded scan stream."""

from __future__ import annotations

import argparse
from pathlib import Path

from rich.console import Console

from harness.commands.arguments import (
    add_device_options,
    add_judging_options,
    add_link_option,
    add_node_options,
    check_link_options,
    check_status_regex,
    fault_list,
    link_options,
    seed,
)
from harness.errors import ConfigError
from harness.link_faults import NO_LINK_FAULTS, LinkFaults

NAME = "replay"
HELP = "re-inject a recorded /scan stream (ours or a robot's rosbag2) and judge the node"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "recording", metavar="FILE", help="an MCAP file, a rosbag2 folder or a .db3 file"
    )
    parser.add_argument(
        "--topic",
        metavar="T",
        help="the LaserScan topic to replay (default /scan, or the only LaserScan topic)",
    )
    add_link_option(parser)
    add_judging_options(parser)
    parser.add_argument("--junit-xml", metavar="FILE", help="write a JUnit XML report")
    parser.add_argument(
        "--faults",
        metavar="FAULT[,FAULT]",
        help="link faults on the replayed scans, e.g. lossy_link,delay(mean=0.05) "
        "(see docs/faults.md); the scans themselves are sent as recorded",
    )
    parser.add_argument("--seed", type=seed, help="seed of the link faults (default recorded)")
    parser.add_argument(
        "--record", metavar="FILE", help="write the replayed run as a new MCAP recording"
    )
    add_node_options(parser)
    add_device_options(parser)


def replay_link_faults(text: str | None) -> LinkFaults:
    """--faults for a replay: link faults only, and no re-timing of recorded scans."""
    from harness.faults import build_profile

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
    from harness.replay import replay
    from harness.report.terminal import print_results

    check_link_options(args)
    check_status_regex(args)
    for option, path in (("--junit-xml", args.junit_xml), ("--record", args.record)):
        if path and not Path(path).resolve().parent.is_dir():
            raise ConfigError(f"{option} {path}: its folder does not exist")
    link_faults = replay_link_faults(args.faults)
    recording = read_scans(args.recording, args.topic)
    result = replay(
        recording,
        args.link,
        link_options(args),
        threshold=args.threshold,
        status_pattern=args.status_regex,
        link_faults=link_faults,
        seed=args.seed,
    )
    print_results(console, [result])
    if args.record:
        from harness.record import write_recording

        write_recording(args.record, result)
    if args.junit_xml:
        from harness.report.junit import write_junit

        write_junit(args.junit_xml, [result])
    return 0 if result.ok else 1
