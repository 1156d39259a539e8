"""The bundled reference node as a real process, over real rclpy and Fast DDS."""

from __future__ import annotations

import math
import signal
import sys
import time

import pytest

from harness.reference.scan_logic import analyse_message, status_text

pytestmark = [pytest.mark.ros, pytest.mark.timeout(45)]

INF, NAN = math.inf, math.nan


def expected_answer(msg, threshold: float) -> tuple[str, bool]:
    """What the node must answer for `msg`, from the pure logic on the float32 ranges."""
    report = analyse_message(msg, threshold)
    return status_text(report), report.warning


def test_answers_each_scan_with_status_and_warning(start_node, ros_graph, make_scan_fn) -> None:
    """Near, far, all-invalid and mixed scans each get the right String and Bool."""
    node = start_node("-p", "threshold:=0.4", "-p", "use_sim_time:=true")
    graph = ros_graph()
    graph.handshake(node)

    near = [INF] * 360
    near[30] = 0.3
    answer = graph.ask(make_scan_fn(near))
    assert answer.warning is True
    assert answer.status == "Min distance: 0.300 m, angle: -2.618 rad"

    far = [INF] * 360
    far[200] = 2.0
    answer = graph.ask(make_scan_fn(far))
    assert (answer.status, answer.warning) == ("Min distance: 2.000 m, angle: 0.349 rad", False)

    answer = graph.ask(make_scan_fn([INF] * 360))
    assert (answer.status, answer.warning) == ("No obstacle detected", False)

    # Every invalid kind below the threshold, one valid reading above it.
    mixed = [-INF, NAN, 0.0, 0.05, 12.5, 0.9] + [INF] * 354
    answer = graph.ask(make_scan_fn(mixed))
    assert (answer.status, answer.warning) == ("Min distance: 0.900 m, angle: -3.054 rad", False)


def test_every_scan_of_a_lockstep_run_is_answered_once(start_node, ros_graph, make_scan_fn) -> None:
    """25 scans in lockstep give 25 Strings and 25 Bools, each matching the pure logic."""
    node = start_node("-p", "threshold:=0.4")
    graph = ros_graph()
    graph.handshake(node)
    for step in range(25):
        ranges = [INF] * 360
        ranges[(step * 37) % 360] = 0.2 + 0.05 * step  # crosses the threshold at step 4
        msg = make_scan_fn(ranges)
        answer = graph.ask(msg)
        assert (answer.status, answer.warning) == expected_answer(msg, 0.4)
        assert (len(graph.statuses), len(graph.warnings)) == (1, 1)


def test_bridge_like_scan_from_angle_zero(start_node, ros_graph, make_scan_fn) -> None:
    """The FOSSBot bridge's header (angle_min 0, 0.15-12 m): the angle is not wrapped."""
    node = start_node()
    graph = ros_graph()
    graph.handshake(node)
    ranges = [INF] * 360
    ranges[270] = 0.45
    answer = graph.ask(make_scan_fn(ranges, angle_min=0.0, range_min=0.15))
    assert (answer.status, answer.warning) == ("Min distance: 0.450 m, angle: 4.712 rad", True)


def test_integer_threshold_is_accepted(start_node, ros_graph, make_scan_fn) -> None:
    """`threshold:=1` (an integer parameter) works as 1.0 m."""
    node = start_node("-p", "threshold:=1")
    graph = ros_graph()
    graph.handshake(node)
    assert graph.ask(make_scan_fn([0.95])).warning is True
    assert graph.ask(make_scan_fn([1.05])).warning is False


def test_topic_parameters_move_every_topic(start_node, ros_graph, make_scan_fn) -> None:
    """lidar_topic, lidar_status_topic and warning_topic are all honoured."""
    node = start_node(
        "-p",
        "lidar_topic:=/robot/scan",
        "-p",
        "lidar_status_topic:=/robot/lidar_text",
        "-p",
        "warning_topic:=/robot/too_close",
    )
    graph = ros_graph("/robot/scan", "/robot/lidar_text", "/robot/too_close")
    graph.handshake(node)
    answer = graph.ask(make_scan_fn([0.25]))
    assert answer.warning is True and answer.status.startswith("Min distance: 0.250 m")
    for default in ("/lidar_status", "/obstacle_warning"):
        assert graph.node.count_publishers(default) == 0
    assert graph.node.count_subscribers("/scan") == 0


# The bundled node as it ships, and with a spin step of an hour: a stop must not wait
# for the executor's step to run out (its signal wake-up ends the spin).
LONG_SPIN_STEP = (
    "import sys; from harness.reference import lidar_node as n; "
    "n.SPIN_STEP_S = 3600.0; sys.exit(n.main())"
)


@pytest.mark.parametrize("spin_step", ["shipped", "an hour"])
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_ends_the_node_cleanly(start_node, ros_graph, make_scan_fn, sig, spin_step) -> None:
    """SIGTERM and SIGINT end a running node with exit code 0 within 5 s, no traceback,
    whatever its executor's spin step."""
    command = [sys.executable, "-c", LONG_SPIN_STEP] if spin_step == "an hour" else None
    node = start_node(command=command)
    graph = ros_graph()
    graph.handshake(node)
    graph.ask(make_scan_fn([1.0]))
    assert node.stop(sig, timeout=5.0) == 0
    node.assert_no_traceback()


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        ("0.0", "> 0"),
        ("-0.4", "> 0"),
        (".nan", "> 0"),
        ("abc", "number"),
        ("true", "number"),
    ],
)
def test_bad_threshold_exits_2_with_a_reason(start_node, value: str, reason: str) -> None:
    """An unusable threshold ends the node at start: exit 2, one FATAL line naming it."""
    node = start_node("-p", f"threshold:={value}")
    assert node.wait(timeout=10.0) == 2
    stderr = node.stderr()
    node.assert_no_traceback()
    assert "FATAL" in stderr and "threshold" in stderr and reason in stderr


@pytest.mark.parametrize(
    "arg",
    ["lidar_topic:=7", "lidar_status_topic:='bad topic'", "scan_qos:=fast"],
    ids=["wrong type", "invalid topic name", "unknown qos"],
)
def test_bad_topic_parameters_exit_2(start_node, arg: str) -> None:
    """Other unusable parameters also end in exit 2 and no traceback."""
    node = start_node("-p", arg)
    assert node.wait(timeout=10.0) == 2
    assert "FATAL" in node.stderr()
    node.assert_no_traceback()


@pytest.mark.parametrize("attempt", range(3))
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_while_scans_stream_in_is_still_clean(
    start_node, ros_graph, make_scan_fn, sig, attempt
) -> None:
    """A signal landing mid-callback or mid-wait still exits 0 without a traceback.

    Regression: rclpy's asynchronous shutdown can surface as RCLError ("context
    is not valid") from the executor or a publish; before the node handled it,
    most of these stops ended in a traceback and exit code 1.
    """
    scan = make_scan_fn([0.3] * 360)
    node = start_node()
    graph = ros_graph()
    graph.handshake(node)
    signal_at = time.monotonic() + 0.2 + 0.05 * attempt
    deadline = signal_at + 5.0
    signalled = False
    # Stream scans (bounded in time) so the node is always mid-answer, signal
    # it, and keep streaming until it has exited.
    while node.popen.poll() is None and time.monotonic() < deadline:
        graph.publisher.publish(scan)
        if not signalled and time.monotonic() >= signal_at:
            node.popen.send_signal(sig)
            signalled = True
    assert signalled
    assert node.wait(timeout=5.0) == 0, node.stderr()
    node.assert_no_traceback()
