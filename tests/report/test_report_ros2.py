"""End to end over the default ros2 link: the reference node, a real DDS graph, --out."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from command_line import fossbot_hil

pytestmark = [pytest.mark.ros, pytest.mark.timeout(180)]


def test_out_over_ros2(tmp_path: Path) -> None:
    """`fossbot-hil run approach_wall --out DIR` as a user types it: a full report."""
    out = tmp_path / "report"
    done = fossbot_hil("run", "approach_wall", "--out", str(out), timeout=150)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Traceback" not in done.stderr and "━" not in done.stdout
    summary = json.loads((out / "summary.json").read_text())
    [entry] = summary["scenarios"]
    assert (summary["ok"], entry["verdict"], entry["link"]) == (True, "PASS", "ros2")
    assert entry["ticks"] > 50 and entry["failed_ticks"] == []
    assert (out / entry["files"]["plot"]).read_bytes()[:4] == b"\x89PNG"
    assert (out / entry["files"]["recording"]).read_bytes()[:5] == b"\x89MCAP"
    details = json.loads((out / entry["files"]["summary"]).read_text())
    assert all(r["status"] for r in details["records"])  # every tick answered over DDS
    assert entry["files"]["plot"] in (out / "index.html").read_text()
    case = ET.parse(out / "junit.xml").getroot().find("./testsuite/testcase")
    assert case is not None and case.get("name") == "approach_wall"
    assert not [p for p in out.rglob(".*")]
