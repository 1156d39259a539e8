"""`fossbot-hil sim`: the lab's world in real time, driven over /cmd_vel, judged while driving."""

from __future__ import annotations

import argparse
import os
from contextlib import AbstractContextManager, nullcontext
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from rich.console import Console

from harness.commands.arguments import (
    FAULTS_METAVAR,
    add_judging_options,
    add_node_options,
    check_output_file,
    domain_id,
    link_options,
    not_empty,
    positive,
    seed,
)
from harness.errors import ConfigError, Interrupted
from harness.report.console_text import print_safe as say
from harness.safe_text import shown

if TYPE_CHECKING:
    from harness.judge.records import RunResult
    from harness.live.session import LiveSession, LiveState
    from harness.scenario.schema import Scenario

NAME = "sim"
HELP = "run a world live: drive the robot over /cmd_vel or the keyboard, watch it, judge a node"
DEFAULT_WORLD = "single_wall"
FOXGLOVE_PORT = 8765  # the Foxglove app's default
DOMAIN_HELP = (
    "ROS_DOMAIN_ID of the live world (default: the shell's ROS_DOMAIN_ID, else 0, so ROS "
    "tools in another terminal see the robot; refused while another fossbot-hil run on "
    "this machine holds it)"
)


def foxglove_port(text: str) -> int | None:
    """--foxglove-port: a TCP port, or ``off``."""
    if text.strip().lower() == "off":
        return None
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a port number or 'off': {text[:40]!r}") from None
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"a port is 1-65535, got {port}")
    return port


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "world",
        nargs="?",
        default=DEFAULT_WORLD,
        metavar="WORLD",
        help=f"a world (default {DEFAULT_WORLD}, the lab's), a shipped scenario's world, "
        "or a scenario file",
    )
    parser.add_argument(
        "--rate",
        type=positive("rate", 100.0),
        default=1.0,
        metavar="X",
        help="simulated seconds per second (default 1: real time)",
    )
    parser.add_argument(
        "--duration",
        type=positive("duration", 86400.0),
        metavar="S",
        help="stop after S simulated seconds (default: run until Ctrl-C)",
    )
    parser.add_argument(
        "--teleop",
        action="store_true",
        help="drive with the keyboard (teleop_twist_keyboard's keys), publishing /cmd_vel",
    )
    parser.add_argument(
        "--foxglove-port",
        type=foxglove_port,
        default=FOXGLOVE_PORT,
        metavar="PORT|off",
        help=f"serve the live view to the Foxglove app here (default {FOXGLOVE_PORT}; off: none)",
    )
    parser.add_argument(
        "--record",
        type=not_empty,
        metavar="FILE.mcap|DIR",
        help="write the judged session as an MCAP recording: to FILE.mcap, or to WORLD.mcap "
        "in the folder DIR (any path not ending in .mcap is a folder, made if need be; needs "
        "a node that answers)",
    )
    parser.add_argument(
        "--animation",
        type=not_empty,
        metavar="FILE",
        help="write the judged session as an animated top-down view to hand in: FILE.gif "
        "(or FILE.mp4 where ffmpeg is installed; needs a node that answers)",
    )
    parser.add_argument(  # the old name (run's --animate is a flag); kept so scripts still work
        "--animate", dest="animation", type=not_empty, help=argparse.SUPPRESS
    )
    parser.add_argument(
        "--seed", type=seed, help="seed of the LIDAR's faults (default: the world's)"
    )
    parser.add_argument(
        "--faults",
        metavar=FAULTS_METAVAR,
        help="sensor fault profiles or inline faults (docs/faults.md); link faults are for `run`",
    )
    add_judging_options(  # live, nothing waits for the node
        parser,
        deadline=False,
        threshold_default="the world's",
        rule_default="the world's, optional in every shipped one",
    )
    add_node_options(
        parser,
        "node under test (default: none; a node started elsewhere is judged too)",
        domain_help=DOMAIN_HELP,
        realtime_help=argparse.SUPPRESS,  # refused: a live world always runs in real time
    )


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.commands.arguments import check_status_regex, judging_settings
    from harness.live.session import LiveSession, LiveSettings
    from harness.live.world import resolve_world

    if args.realtime:
        raise ConfigError("--realtime: a live session always runs in real time (see --rate)")
    check_status_regex(args)
    options = replace(link_options(args), domain_id=_domain(args.domain_id))
    scenario = resolve_world(args.world)
    args.record = _recording_path(args.record, scenario.name)
    check_output_file("--record", args.record)
    check_output_file("--animation", args.animation)
    _check_animation_suffix(args.animation)
    node = bool(args.node or args.package or args.executable)
    settings = LiveSettings(
        rate=args.rate, duration=args.duration, node=node, run=judging_settings(args)
    )

    def ready(domain: int) -> None:
        reach = "this machine" if not options.ros_network else "the network"
        say(
            console,
            f"{scenario.name} is live on ROS_DOMAIN_ID={domain} ({reach}): /cmd_vel in; "
            "/scan, /odom, /clock out. Ctrl-C ends it.",
        )

    shown = _Panel(console, judging=node)
    try:
        with _view(scenario, args.foxglove_port) as view, _keys(args.teleop) as keys, shown:
            if view is not None:
                say(console, f"Foxglove: open {view.url} in the Foxglove app (Open connection)")
                for note in view.notes:
                    say(console, f"note: {note}")
            session = LiveSession(
                scenario,
                options,
                settings,
                on_ready=ready,
                on_update=shown.update,
                keys=keys,
                view=view,
                show=lambda line: say(console, line),
            )
            result = session.run()
    except KeyboardInterrupt as err:  # while starting, before the session can end itself
        say(console, f"stopped by {Interrupted.of(err).name} before the world ran")
        return 0
    _summary(console, session, result)
    _evidence(console, args, scenario, result)
    return 0 if result is None or result.ok else 1


def _view(scenario: Scenario, port: int | None) -> AbstractContextManager[Any]:
    """The Foxglove live view on `port`, or none (--foxglove-port off)."""
    if port is None:
        return nullcontext(None)
    from harness.live.foxglove_view import FoxgloveView

    return FoxgloveView(scenario, port=port)


def _keys(teleop: bool) -> AbstractContextManager[Any]:
    """The terminal's keys for --teleop (ConfigError when there is no terminal), or none."""
    if not teleop:
        return nullcontext(None)
    from harness.live.teleop import KeyReader

    return KeyReader()


class _Panel:
    """The live panel on a terminal (redrawn by rich a few times a second); nothing elsewhere."""

    def __init__(self, console: Console, *, judging: bool) -> None:
        from rich.live import Live

        self.judging = judging
        self._live = Live(console=console, refresh_per_second=4) if console.is_terminal else None

    def update(self, state: LiveState) -> None:
        if self._live is not None:
            from harness.live.panel import panel

            judging = self.judging or state.judged > 0
            self._live.update(panel(state, judging=judging), refresh=False)

    def __enter__(self) -> _Panel:
        if self._live is not None:
            self._live.start()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._live is not None:
            self._live.stop()


def _recording_path(path: str | None, world: str) -> str | None:
    """--record PATH: a .mcap file as given, else WORLD.mcap inside the folder PATH (made
    if need be, as --out makes its folder; the world's name made a safe file name)."""
    if path is None or path.endswith(".mcap"):
        return path
    try:
        os.makedirs(path, exist_ok=True)
    except (OSError, ValueError) as err:
        reason = getattr(err, "strerror", None) or err
        raise ConfigError(f"--record {shown(path)}: cannot make this folder: {reason}") from None
    from harness.report.outputs import safe_stem

    return os.path.join(path, f"{safe_stem(world)}.mcap")


ANIMATION_SUFFIXES = (".gif", ".mp4")  # what harness.report.animation writes


def _check_animation_suffix(path: str | None) -> None:
    """An --animation file it cannot write is a usage error now, not after the session."""
    if path is not None and os.path.splitext(path)[1].lower() not in ANIMATION_SUFFIXES:
        raise ConfigError(
            f"--animation {shown(path)}: an animation is written as .gif (or .mp4 with ffmpeg)"
        )


EVIDENCE = (("--record", "record"), ("--animation", "animation"))  # option, dest


def _evidence(
    console: Console, args: argparse.Namespace, scenario: Scenario, result: RunResult | None
) -> None:
    """--record and --animation: what the lab asks students to hand in."""
    wanted = [option for option, dest in EVIDENCE if getattr(args, dest)]
    if not wanted:
        return
    if result is None:
        say(console, f"{' and '.join(wanted)}: nothing was judged, so nothing was written")
        return
    if args.record:
        from harness.record.writer import write_recording

        write_recording(args.record, result)
        say(console, f"recording: {args.record}")
    if args.animation:
        from harness.report.animation import write_animation

        write_animation(result, scenario, args.animation)
        say(console, f"animation: {args.animation}")


def _domain(given_id: int | None) -> int:
    """The session's domain: --domain-id, else the shell's ROS_DOMAIN_ID (0 if unset), so
    the user's own ROS tools in another terminal (teleop, rviz2) see the robot."""
    if given_id is not None:
        return given_id
    text = os.environ.get("ROS_DOMAIN_ID", "").strip() or "0"
    try:
        return domain_id(text)
    except argparse.ArgumentTypeError as err:
        raise ConfigError(f"ROS_DOMAIN_ID={text[:20]!r} in the environment: {err}") from None


def _summary(console: Console, session: LiveSession, result: RunResult | None) -> None:
    """How the session went: its speed, what it heard, and the judge's verdict."""
    stats = session.stats
    say(
        console,
        f"{session.scenario.name}: {stats.sim_s:.1f} s simulated in {stats.wall_s:.1f} s "
        f"({stats.real_time_factor:.2f}x real time, asked {session.settings.rate:g}x), "
        f"{stats.scans} scans, {stats.commands} /cmd_vel commands; ended by {stats.stopped_by}",
    )
    pose = session.state.pose
    say(console, f"the robot ended at x {pose.x:.2f} m, y {pose.y:.2f} m, yaw {pose.yaw:.2f} rad")
    if stats.late_slices:
        say(
            console,
            f"note: {stats.late_slices} slices of 1/60 s ran late: this machine could not keep "
            f"{session.settings.rate:g}x real time all along (try a lower --rate)",
        )
    for note in session.notes:
        say(console, f"note: {note}")
    if result is None:
        say(console, "no node answered: nothing was judged")
        return
    from harness.report.terminal import print_results

    print_results(console, [result])
