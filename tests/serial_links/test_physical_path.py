"""The physical-board path (--port), exercised here through a pty null-modem cable.

The harness opens a serial device path with pyserial, exactly as it opens a
USB-UART, paces the line in real time, and joins the board's ROS domain;
the "board" on the other end is the bundled driver and reference node. The
same test against real hardware is tests/hil (run with --hil-port).
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest
from command_line import REAL_TIME_DEADLINE
from far_end import REFERENCE_NODE, FarEnd, bundled_driver

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

SHORT = (
    "description: Two seconds facing a wall.\n"
    "obstacles: [{type: wall, start: [0.4, -1.0], end: [0.4, 1.0]}]\n"
    "motion: {segments: [{until: {duration: 2.0}}]}\n"
)


def start_harness(far_end: FarEnd, scenario: Path, *extra: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "harness.cli",
            "run",
            str(scenario),
            "--link",
            "rplidar",
            "--port",
            far_end.cable.harness_end,
            "--domain-id",
            str(far_end.domain_id),
            *extra,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_run_against_a_board_on_a_serial_port(far_end: FarEnd, tmp_path: Path) -> None:
    """--port with --domain-id: real-time emulation into the board, its answers judged."""
    scenario = tmp_path / "facing_wall.yaml"
    scenario.write_text(SHORT)
    harness = start_harness(far_end, scenario, *REAL_TIME_DEADLINE)
    far_end.start(harness, bundled_driver(far_end.cable.board_end), REFERENCE_NODE)
    out, err = harness.communicate(timeout=90)
    assert harness.returncode == 0, out + err
    assert "1 of 1 scenario passed" in out


def test_unplugged_adapter_fails_the_run_promptly(far_end: FarEnd, tmp_path: Path) -> None:
    """Pulling the cable mid-run ends the run with a clear message, not a hang.

    Until the cut the board answers in real time: a generous deadline, as for the other
    real-time runs (the cut is noticed on the line, not by a deadline waited out)."""
    scenario = tmp_path / "long.yaml"
    scenario.write_text(SHORT.replace("duration: 2.0", "duration: 30.0"))
    harness = start_harness(far_end, scenario, *REAL_TIME_DEADLINE)
    far_end.start(harness, bundled_driver(far_end.cable.board_end), REFERENCE_NODE)
    time.sleep(6.0)  # the run is under way by then (not synchronisation: any moment will do)
    cut_at = time.monotonic()
    far_end.cable.cut()
    out, err = harness.communicate(timeout=30)
    elapsed = time.monotonic() - cut_at
    assert harness.returncode == 1, out + err
    assert "link lost" in out, out + err
    assert elapsed < 5.0, f"the run took {elapsed:.1f} s to notice the unplugged adapter"


@pytest.mark.parametrize(
    ("link", "expected"),
    [
        (
            "rplidar",
            [
                "the board never became ready within 2 s",
                "came back nothing (0 bytes)",
                "likely cause: the board never sent a request",
            ],
        ),
        (
            "ldlidar",
            [
                "the board never became ready within 2 s (LDROBOT LD06/LD19",
                "came back nothing (0 bytes)",
                "likely cause: an LD06/LD19 driver sends nothing back, so the line cannot tell",
                "not ready in ROS domain {domain}: check that it is the board's",
            ],
        ),
    ],
)
def test_a_board_that_never_answers_is_told_what_went_down_the_line(
    far_end: FarEnd, tmp_path: Path, link: str, expected: list[str]
) -> None:
    """Nothing on the far end: the error says what was sent, that nothing came back, and
    why; an LD06/LD19 line says nothing back, so its error names the ROS 2 side."""
    scenario = tmp_path / "facing_wall.yaml"
    scenario.write_text(SHORT)
    harness = subprocess.run(
        [
            *(sys.executable, "-m", "harness.cli", "run", str(scenario), "--link", link),
            *("--port", far_end.cable.harness_end, "--domain-id", str(far_end.domain_id)),
            *("--ready-timeout", "2"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    text = harness.stdout + harness.stderr
    assert harness.returncode == 1, text
    for line in expected:
        assert line.format(domain=far_end.domain_id) in text, text
