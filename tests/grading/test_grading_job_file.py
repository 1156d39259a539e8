"""A grading or audit worker reads back the run its job file describes, field for field."""

from __future__ import annotations

import json
from pathlib import Path

from harness.grading.worker import link_options_from, run_settings_from, write_job
from harness.lidar.mount import LidarMount
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings


def test_link_options_and_settings_survive_the_job_file(tmp_path: Path) -> None:
    """JSON has no tuples and no dataclasses: only `params` used to come back as it went
    (a launch pair, the topic parameters, board commands and the LIDAR mount came back as
    lists and a dict)."""
    options = LinkOptions(
        threshold=0.4,
        params=("a:=1", "b:=2"),
        launch=("fossbot_lidar_processing", "lidar.launch.py"),
        topic_params=("scan_in", "status_out", "warn_out"),
        board_commands=("python3 agent.py {port}", "python3 bridge.py"),
        lidar_mount=LidarMount(yaw_deg=-90.0, mirrored=True),
        scan_timeout=0.7,
    )
    settings = RunSettings(seed=7, threshold=0.4, stop_at_first_failure=True)
    job_file = write_job(
        tmp_path / "job.json",
        scenarios=["approach_wall"],
        link="rplidar",
        options=options,
        settings=settings,
        results=tmp_path / "results.json",
        junit=tmp_path / "junit.xml",
    )
    job = json.loads(job_file.read_text())
    assert link_options_from(job["options"]) == options
    assert run_settings_from(job["settings"]) == settings
