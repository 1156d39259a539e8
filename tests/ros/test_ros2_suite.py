"""The default suite over real DDS: the reference node and student-style nodes.

Every node runs in its own process, started by the real `fossbot-hil`
command, and talks to the harness over Fast DDS in its own domain.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest
from command_line import fossbot_hil
from deadlines import short_deadline

pytestmark = [pytest.mark.ros, pytest.mark.timeout(300)]

STUDENT = Path(__file__).parent / "student_node.py"


def student(variant: str) -> str:
    return f"{sys.executable} {STUDENT} {variant}"


def test_default_run_is_the_whole_suite_over_ros2() -> None:
    """`fossbot-hil run` with no arguments: every shipped scenario, reference node, ros2."""
    done = fossbot_hil("run")
    assert done.returncode == 0, done.stdout + done.stderr
    for name in ("approach_wall", "drive_past_10m", "out_of_range", "rotate_beside_wall"):
        assert f"{name} " in done.stdout
    assert " ros2 " in done.stdout and "FAIL" not in done.stdout


@pytest.mark.parametrize("variant", ["correct", "correct_bool_when_close"])
def test_correct_students_pass(variant: str) -> None:
    """Other wording, and a Bool published only when close, are right."""
    done = fossbot_hil("run", "--node", student(variant))
    assert done.returncode == 0, done.stdout + done.stderr


# Bug -> a shipped scenario that catches it, and a phrase its explanation must contain.
# That the whole default suite catches each is shown in process (test_inprocess_suite.py)
# and by the audit (tests/audit/): over DDS, one scenario each keeps the suite short.
BUGS = {
    "min_over_raw_ranges": ("out_of_range", "expected"),
    "no_range_min_filter": ("out_of_range", "expected no obstacle"),
    "angle_without_angle_min": ("approach_wall", "expected angle"),
    "angle_in_degrees": ("obstacle_at_side", "looks like degrees"),
    "no_bool": ("approach_wall", "got no Bool"),
    "inverted_bool": ("approach_wall", "expected warning"),
    "threshold_hard_coded": (
        "obstacle_at_side",
        "the node warns as if its threshold were between 0.4",
    ),
    "answers_twice": ("approach_wall", "answered twice"),
    "unparseable": ("approach_wall", "obstacle: yes-ish"),
}


@pytest.mark.parametrize(("variant", "caught"), BUGS.items())
def test_buggy_student_is_caught_over_dds(variant: str, caught: tuple[str, str]) -> None:
    """Each bug fails a shipped scenario; the explanation names scenario, tick and
    expectation."""
    scenario, phrase = caught
    done = fossbot_hil("run", scenario, "--node", student(variant))
    assert done.returncode == 1, done.stdout + done.stderr
    assert " tick " in done.stdout and phrase in done.stdout, done.stdout
    assert f"{scenario}: t=" in done.stdout, done.stdout


def test_crash_when_nothing_in_range_shows_exit_code_and_stderr() -> None:
    """A node that dies mid-run: its exit code and last stderr lines are shown."""
    done = fossbot_hil("run", "drive_past_10m", "--node", student("crash_when_nothing_in_range"))
    assert done.returncode == 1
    assert "exited with code 1" in done.stdout and "ValueError" in done.stdout


def test_slow_callbacks_are_too_late_then_stopped() -> None:
    """Answers slower than the deadline fail, say when they came, and end the run."""
    done = fossbot_hil(
        "run", "approach_wall", "--timeout", "0.5", "--node", student("slow_callback")
    )
    assert done.returncode == 1
    # The node sleeps 1.5 s per scan; on a loaded machine its answer comes a little later.
    came = re.search(
        r"no status within the deadline \(0\.50 s\); it came after (\d+\.\d+) s", done.stdout
    )
    assert came is not None and float(came.group(1)) >= 1.5, done.stdout
    assert "node answers too late: 3 scans in a row missed the 0.5 s deadline" in done.stdout


def test_node_that_stops_answering_ends_the_run() -> None:
    """A node that goes silent mid-run: a bounded wait, then a clear end.

    Ticks 0-9 must be answered in time, tick 10 on waited out: a deadline short, but
    measured against this machine's load."""
    deadline = f"{short_deadline():g}"
    done = fossbot_hil(
        "run", "approach_wall", "--timeout", deadline, "--node", student("goes_silent")
    )
    assert done.returncode == 1
    # The node answers 10 scans: ticks 0-9 (the first scan is tick 0's, judged).
    assert "tick 10: " in done.stdout and "no status within the deadline" in done.stdout
    assert "node stopped answering: no status on /lidar_status for 3 scans" in done.stdout


def test_ignored_topic_parameter_never_becomes_ready() -> None:
    """A node that ignores lidar_topic never subscribes to the harness's scan topic."""
    done = fossbot_hil(
        "run",
        "approach_wall",
        "--node",
        student("topic_parameter_ignored"),
        "--param",
        "lidar_topic:=/robot/scan",
        "--scan-topic",
        "/robot/scan",
        "--ready-timeout",
        "3",
    )
    assert done.returncode == 1
    assert "never became ready within " in done.stdout
    assert "subscribers on /robot/scan: 0" in done.stdout


def test_a_node_reading_another_scan_topic_is_told_so_without_waiting_out_readiness() -> None:
    """The graph shows the node reading LaserScans on /scan, not the harness's topic: the
    run says so about a second later, not after the whole readiness bound (20 s)."""
    done = fossbot_hil(
        "run",
        "approach_wall",
        *("--node", student("topic_parameter_ignored")),
        *("--param", "lidar_topic:=/robot/scan", "--scan-topic", "/robot/scan"),
    )
    assert done.returncode == 1, done.stdout + done.stderr
    waited = re.search(r"never became ready within (\d+\.\d) s \(of the 20 s allowed", done.stdout)
    assert waited is not None, done.stdout
    assert float(waited.group(1)) < 20
    assert "it subscribes to a LaserScan on /scan, not /robot/scan" in done.stdout


def test_a_node_that_names_its_warning_parameter_otherwise_is_told_which_parameter() -> None:
    """obstacle_at_side sets the node's topics through the lab's parameters; a node that
    declares obstacle_warning_topic, not warning_topic, is told the parameter it did not
    take and the option that names its own, not only the topic it used instead."""
    done = fossbot_hil("run", "obstacle_at_side", "--node", student("own_warning_parameter"))
    assert done.returncode == 0, done.stdout + done.stderr
    note = next(line for line in done.stdout.splitlines() if line.startswith("note: "))
    assert "did not take the parameter warning_topic:=/fossbot2/obstacle_warning" in note
    assert "(it declares obstacle_warning_topic)" in note
    assert "pass --param obstacle_warning_topic:=/fossbot2/obstacle_warning" in note
    assert "--warning-topic" not in note


def test_non_default_topics_and_threshold_as_parameters() -> None:
    """Topics and threshold passed to the node as parameters, matched by the harness."""
    done = fossbot_hil(
        "run",
        "obstacle_at_side",
        "approach_wall",
        "--threshold",
        "0.35",
        "--param",
        "lidar_topic:=/robot/scan",
        "--scan-topic",
        "/robot/scan",
        "--param",
        "lidar_status_topic:=/robot/status",
        "--status-topic",
        "/robot/status",
        "--param",
        "warning_topic:=/robot/too_close",
        "--warning-topic",
        "/robot/too_close",
    )
    assert done.returncode == 0, done.stdout + done.stderr


def test_node_that_exits_before_ready() -> None:
    """A node that exits at once: its exit code, not a hang."""
    done = fossbot_hil(
        "run", "approach_wall", "--node", f"{sys.executable} -c 'import sys; sys.exit(3)'"
    )
    assert done.returncode == 1
    assert "exited with code 3 before it was ready" in done.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--node", "no-such-program --x"], "'no-such-program' not found on PATH"),
        (["--node", "./nope.py"], "no such file ./nope.py"),
        (["--package", "fossbot_lidar_processing"], "--package and --executable go together"),
        (["--package", "p", "--executable", "e", "--workspace", "/nonexistent"], "no such folder"),
        (["--param", "threshold=0.3"], "expected NAME:=VALUE"),
        (["--domain-id", "999"], "domain id must be"),
    ],
)
def test_bad_node_options_exit_2(args: list[str], needle: str) -> None:
    """Bad node options: exit 2 with one line, before anything starts."""
    done = fossbot_hil("run", "approach_wall", *args, timeout=60)
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stderr.count("\n") == 1 and needle in done.stderr


def test_junit_report(tmp_path: Path) -> None:
    """--junit-xml: one case per scenario, the oracle's explanation as the failure."""
    report = tmp_path / "report.xml"
    done = fossbot_hil(
        "run",
        "approach_wall",
        "rotate_beside_wall",
        "--node",
        student("angle_in_degrees"),
        "--junit-xml",
        str(report),
    )
    assert done.returncode == 1
    xml = report.read_text()
    assert 'tests="2"' in xml and "looks like degrees" in xml and 'name="seed"' in xml


def test_realtime_mode_paces_scans_at_the_sensor_rate(tmp_path: Path) -> None:
    """--realtime: scans go out at the LIDAR's rate (never faster) and are still judged.

    In real time each answer is due before the next scan: the period is the deadline,
    and every period is waited out. The LIDAR's rate is set so that its period is a
    short deadline measured against this machine's load (at 10 Hz a loaded machine's
    answer could miss its 0.1 s)."""
    period = short_deadline()
    scenario = tmp_path / "beside_wall.yaml"
    scenario.write_text(
        "description: One and a half periods beside a wall.\n"
        f"lidar: {{preset: gazebo, rate_hz: {1 / period!r}}}\n"
        "obstacles: [{type: wall, start: [0.4, -1.0], end: [0.4, 1.0]}]\n"
        f"motion: {{segments: [{{until: {{duration: {1.5 * period!r}}}}}]}}\n"
    )
    done = fossbot_hil("run", str(scenario), "--realtime", "--junit-xml", str(tmp_path / "r.xml"))
    assert done.returncode == 0, done.stdout + done.stderr
    xml = (tmp_path / "r.xml").read_text()
    assert 'name="ticks" value="3"' in xml  # at 0, 1 and 2 periods (the end pose)
    wall = float(xml.split('name="beside_wall" time="')[1].split('"')[0])
    assert wall >= 2 * period  # two periods, at the least


def test_the_strict_warning_rule_fails_a_bool_only_when_close() -> None:
    """The lab allows a Bool only when True; --warning-when-clear required does not."""
    node = student("correct_bool_when_close")
    lenient = fossbot_hil("run", "approach_wall", "--node", node)
    assert lenient.returncode == 0, lenient.stdout + lenient.stderr
    strict = fossbot_hil("run", "approach_wall", "--node", node, "--warning-when-clear", "required")
    assert strict.returncode == 1, strict.stdout + strict.stderr
    assert "expected warning False; got no Bool" in strict.stdout
    assert "judged with --warning-when-clear required" in strict.stdout
    assert "judged with --warning-when-clear" not in lenient.stdout


def test_a_node_deaf_to_one_scenarios_topics_still_runs_the_next_scenarios() -> None:
    """obstacle_at_side gives the node its topics through its parameters; a node that
    ignores lidar_topic never reads that scenario's scans (ERROR there), but it is up, and
    the next scenario, on the lab's topics, runs and passes."""
    done = fossbot_hil(
        "run", "obstacle_at_side", "approach_wall", "--node", student("topic_parameter_ignored")
    )
    assert done.returncode == 1, done.stdout + done.stderr
    assert re.search(r"^obstacle_at_side\s+ros2\s+0\s+0\s+ERROR", done.stdout, re.M), done.stdout
    assert re.search(r"^approach_wall\s+ros2\s+\d+\s+0\s+PASS", done.stdout, re.M), done.stdout
    assert "it subscribes to a LaserScan on /scan, not /fossbot2/scan" in done.stdout
