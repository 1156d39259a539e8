"""Hostile nodes: each misbehaviour gets a clear verdict in bounded time, and nothing survives.

Every node is a real process (tests/ros/hostile_node.py) over real DDS. It
writes its pid, and the pids of every process it starts, to a file; after
the run none of them may be alive. A node that answers gets a generous
deadline, which its answers never wait out; a node that leaves scans
unanswered (it hangs, or answers in the wrong type) waits out theirs, each
short but measured against this machine's load (tests/deadlines.py). Each
test takes seconds; the timeout marker is only a backstop.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from command_line import COMMAND, fossbot_hil
from deadlines import GENEROUS_READY_S, GENEROUS_S, short_deadline

from harness.errors import LinkError
from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.links.ros2 import Ros2Link
from harness.runner.scenario_run import run
from harness.scenario.files import resolve_scenario

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]

HOSTILE = Path(__file__).parent / "hostile_node.py"
SCENARIO = Path(__file__).parent / "hostile_wall.yaml"  # 21 ticks, a wall 0.4 m ahead
# Each scan's deadline: an answer that comes never waits it out, so it is generous; tests
# whose node leaves a scan unanswered set a short one (tests/deadlines.py).
TIMEOUT_S = GENEROUS_S
# The bound for a node's start and its first answer: a node that comes up never waits it
# out, nor does one on the wrong topics (told as soon as the graph shows them).
READY_S = GENEROUS_READY_S
RUN_LIMIT_S = 45  # the CLI run, bounded


def node(variant: str, pids: Path) -> str:
    return f"{sys.executable} {HOSTILE} {variant} --pids {pids}"


def hostile_cli(
    variant: str, pids: Path, *extra: str, timeout: float = TIMEOUT_S
) -> subprocess.CompletedProcess[str]:
    """`fossbot-hil run` against the variant, `timeout` each scan's deadline; no harness
    traceback, ever."""
    done = fossbot_hil(
        "run",
        str(SCENARIO),
        "--timeout",
        f"{timeout:g}",
        "--ready-timeout",
        f"{READY_S:g}",
        "--node",
        node(variant, pids),
        *extra,
        timeout=RUN_LIMIT_S,
    )
    assert "Traceback" not in done.stderr, done.stderr
    return done


def hostile_api(variant: str, pids: Path) -> RunResult:
    """The same run through the runner API, for what only the result's diagnostics show."""
    options = LinkOptions(node=node(variant, pids), scan_timeout=TIMEOUT_S, ready_timeout=READY_S)
    return run(resolve_scenario(str(SCENARIO)), "ros2", options)


def recorded(pids: Path) -> list[tuple[int, str]]:
    """(pid, start time) of the node and of each process it started."""
    lines = [line.split() for line in pids.read_text().splitlines()]
    return [(int(fields[0]), fields[1]) for fields in lines if len(fields) == 2]


def alive(pid: int, started: str) -> bool:
    """That very process (same start time) still exists and is not a zombie."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    fields = stat.rsplit(")", 1)[1].split()
    return fields[19] == started and fields[0] != "Z"


def survivors(pids: Path) -> list[int]:
    return [pid for pid, started in recorded(pids) if alive(pid, started)]


@pytest.fixture
def pids(tmp_path: Path):
    """The file the node writes its pids to; whatever a failed test leaves is killed."""
    path = tmp_path / "pids"
    yield path
    if path.exists():
        for pid in survivors(path):
            subprocess.run(["kill", "-9", str(pid)], check=False)


def explanation(done: subprocess.CompletedProcess[str]) -> str:
    return done.stdout + done.stderr


def says(done: subprocess.CompletedProcess[str], *phrases: str) -> None:
    """Each phrase is in the CLI's output (shown whole when one is missing)."""
    missing = [p for p in phrases if p not in done.stdout]
    assert not missing, f"missing {missing} in:\n{explanation(done)}"


def test_crash_at_start(pids: Path) -> None:
    """Exits before it is ready: its exit code and last stderr line, at once."""
    done = hostile_cli("crash_at_start", pids)
    assert done.returncode == 1, explanation(done)
    says(
        done,
        "exited with code 1 before it was ready",
        "RuntimeError: hostile: crash before the node exists",
    )
    assert len(recorded(pids)) == 1 and survivors(pids) == []


def test_crash_mid_run(pids: Path) -> None:
    """Raises in the callback of tick 2's scan: tick 2 names the crash."""
    done = hostile_cli("crash_mid_run", pids)
    assert done.returncode == 1, explanation(done)
    says(
        done,
        "hostile_wall: t=0.20 s tick 2: ",
        "crashed on this scan: it exited with code 1; last stderr:",
        "RuntimeError: hostile: crash in the callback of the scan stamped 0.2 s",
    )
    assert survivors(pids) == []


def test_crash_on_the_first_scan_is_tick_0s_failure_naming_the_node_once(pids: Path) -> None:
    """Raises on the first scan, which is tick 0's: tick 0 fails with 'node CMD crashed on
    this scan', its exit code and the exception, CMD once."""
    done = hostile_cli("crash_on_first_scan", pids)
    assert done.returncode == 1, explanation(done)
    command = node("crash_on_first_scan", pids)
    says(
        done,
        "hostile_wall: t=0.00 s tick 0: ",
        f"node {command} crashed on this scan: it exited with code 1; last stderr: "
        "RuntimeError: hostile: crash in the callback of the first scan (hostile_node.py line",
    )
    assert "link problem" not in done.stdout and "run ended" not in done.stdout
    first = next(line for line in done.stdout.splitlines() if line.startswith("hostile_wall:"))
    assert first.count(command) == 1, first
    assert survivors(pids) == []


def test_hang_in_callback(pids: Path) -> None:
    """Blocks forever in a callback: three missed deadlines end the run; the node is stopped.

    Ticks 0 and 1 must be answered in time, tick 2 on waited out: a deadline short, but
    measured against this machine's load."""
    deadline = short_deadline()
    done = hostile_cli("hang", pids, timeout=deadline)
    assert done.returncode == 1, explanation(done)
    says(
        done,
        "tick 2: ",
        f"no status within the deadline ({deadline:.2f} s)",
        "node stopped answering: no status on /lidar_status for 3 scans in a row",
    )
    assert survivors(pids) == []


def test_exit_code_0_mid_run_is_an_error(pids: Path) -> None:
    """'Finishing' after a few scans is not a pass."""
    done = hostile_cli("exits_early", pids)
    assert done.returncode == 1, explanation(done)
    says(done, "tick 2: ", "exited with code 0 (finished on its own: a node must keep running")
    assert survivors(pids) == []


@pytest.mark.parametrize(
    ("variant", "topic"),
    [("flood_status", "/lidar_status"), ("flood_warning", "/obstacle_warning")],
)
def test_message_flood_ends_the_run(variant: str, topic: str, pids: Path) -> None:
    """Publishing as fast as it can on a topic: the run ends, naming the topic and the count.

    The flood holds back the first answer (the node's callback shares its interpreter with
    the flooding thread, the harness hears the flood too), which the ready timeout bounds:
    a loaded machine's came after more than 5 s ('never answered a scan within 5 s'), so
    READY_S is generous; the flood ends the run at the first answer."""
    done = hostile_cli(variant, pids)
    assert done.returncode == 1, explanation(done)
    says(done, f"node floods {topic}: ", "(one per scan expected)")
    assert survivors(pids) == []


def test_output_flood_is_drained_and_only_its_tail_kept(pids: Path) -> None:
    """Megabytes on stdout and stderr: no blocked node, no growing buffer, the tail shown."""
    result = hostile_api("flood_output", pids)
    assert result.ok, result.first_failure
    assert "node stdout: " in result.diagnostics and "MB written" in result.diagnostics, (
        result.diagnostics
    )
    assert "node stderr (last lines):\nxxxx" in result.diagnostics
    assert len(result.diagnostics) < 20_000  # two 15-line tails and a few notes
    assert survivors(pids) == []


def test_a_bool_held_up_in_the_node_still_answers_its_scan(pids: Path) -> None:
    """A Bool published after the next scan went out, but before the node's next String,
    answers the scan before: no 'got no Bool' here and two Bools there."""
    result = hostile_api("bool_held_up", pids)
    assert result.ok, result.first_failure
    assert len(result.records) >= 15
    assert [len(r.answers.warnings) for r in result.records] == [1] * len(result.records)
    assert survivors(pids) == []


@pytest.mark.parametrize(
    ("variant", "wrong"),
    [
        ("status_as_bool", "publishes /lidar_status as std_msgs/msg/Bool"),
        (
            "warning_as_int32",
            "/fossbot_lidar_node publishes /obstacle_warning as std_msgs/msg/Int32",
        ),
    ],
)
def test_wrong_message_type_is_named(variant: str, wrong: str, pids: Path) -> None:
    """DDS never connects different types: the graph says which topic has which type.

    No answer of the right type comes (the Int32 node's first Bool is waited for, one
    deadline): a short deadline, measured against this machine's load."""
    done = hostile_cli(variant, pids, timeout=short_deadline())
    assert done.returncode == 1, explanation(done)
    says(done, "uses the wrong message type: ", wrong, "but the harness expects std_msgs/msg/")
    assert survivors(pids) == []


def test_best_effort_publisher_is_named(pids: Path) -> None:
    """A best-effort status never matches the harness's reliable subscription: said at once."""
    done = hostile_cli("best_effort", pids)
    assert done.returncode == 1, explanation(done)
    says(done, "cannot be heard: ", "publishes /lidar_status best-effort, but the harness")
    assert survivors(pids) == []


@pytest.mark.parametrize(
    ("variant", "extra", "publishes"),
    [
        ("status_topic_wrong", (), "/lidar_status_wrong (std_msgs/msg/String)"),
        (
            "status_parameter_ignored",
            ("--param", "lidar_status_topic:=/robot/status", "--status-topic", "/robot/status"),
            "/lidar_status (std_msgs/msg/String)",
        ),
    ],
)
def test_wrong_topic_names_are_listed(
    variant: str, extra: tuple[str, ...], publishes: str, pids: Path
) -> None:
    """A status on another topic: 'never ready', what was missing, what the node does publish."""
    done = hostile_cli(variant, pids, *extra)
    assert done.returncode == 1, explanation(done)
    status = extra[-1] if extra else "/lidar_status"
    says(
        done,
        "never became ready within ",
        f"of the {READY_S:g} s allowed: it uses other topics",  # told once the graph shows them
        "the harness waited for it to subscribe to /scan and "
        f"publish {status}, but it did not publish {status} (subscribers on /scan: 1",
        f"/fossbot_lidar_node publishes {publishes}, /obstacle_warning",
        "subscribes to /scan (sensor_msgs/msg/LaserScan)",
    )
    assert "/clock" not in done.stdout  # it reads the scans: /clock is no suspect
    assert survivors(pids) == []


def test_a_node_waiting_for_clock_before_it_subscribes_starts_and_passes(pids: Path) -> None:
    """The harness publishes /clock (time 0) while it waits for the node to come up."""
    done = hostile_cli("waits_for_clock", pids)
    assert done.returncode == 0, explanation(done)
    says(done, "1 of 1 scenario passed")
    assert survivors(pids) == []


def clock_only_when_ready(options: LinkOptions) -> Ros2Link:
    """The ros2 link as into a physical board's graph: no /clock before the node is ready."""
    link = Ros2Link(options)
    link.graph._clock_before_ready = lambda: False  # type: ignore[method-assign]
    return link


def test_never_ready_says_clock_comes_only_once_the_node_is_ready(pids: Path) -> None:
    """No /clock before it is ready: the clock-waiting node never subscribes, and is told why."""
    # Long enough for the node to publish its status topic on a loaded machine (tests in parallel).
    options = LinkOptions(node=node("waits_for_clock", pids), ready_timeout=6.0)
    link = clock_only_when_ready(options)
    try:
        with pytest.raises(LinkError) as never:
            link.open()
    finally:
        link.close()
    message = str(never.value)
    assert (
        "never became ready within 6 s: the harness waited for it to subscribe to /scan and "
        "publish /lidar_status, but it did not subscribe to /scan (the harness publishes /clock "
        "only once the node is ready, so a node that waits for /clock before it subscribes to "
        "/scan never starts) (subscribers on /scan: 0, publishers on /lidar_status: 1"
    ) in message, message
    assert survivors(pids) == []


def test_node_ignoring_sigint_and_sigterm_is_killed(pids: Path) -> None:
    """Closing escalates to SIGKILL after bounded waits, and the diagnostics say so."""
    result = hostile_api("ignores_signals", pids)
    assert result.ok, result.first_failure
    assert "ignored SIGINT (2 s) and SIGTERM (1 s): killed with SIGKILL, " in result.diagnostics, (
        result.diagnostics
    )
    assert survivors(pids) == []


def test_processes_the_node_leaves_behind_are_killed(pids: Path) -> None:
    """A child in its own session ignoring signals, and a double-forked daemon: both go."""
    result = hostile_api("leaves_children", pids)
    assert result.ok, result.first_failure
    assert len(recorded(pids)) == 3
    assert "left 2 processes running after it stopped (killed)" in result.diagnostics, (
        result.diagnostics
    )
    assert survivors(pids) == []


def test_nothing_survives_a_killed_harness(pids: Path) -> None:
    """SIGKILL the harness mid-start: the node's reaper still stops the node and its strays."""
    harness = subprocess.Popen(
        [*COMMAND, "run", str(SCENARIO), "--node", node("leaves_children", pids)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and not (pids.exists() and len(recorded(pids)) == 3):
        time.sleep(0.05)  # bounded poll: the node and both strays are up
    assert len(recorded(pids)) == 3
    harness.send_signal(signal.SIGKILL)
    assert harness.wait(timeout=10) == -signal.SIGKILL
    deadline = time.monotonic() + 20
    while survivors(pids) and time.monotonic() < deadline:
        time.sleep(0.05)  # bounded poll: Linux tells the reaper its parent died
    assert survivors(pids) == []
