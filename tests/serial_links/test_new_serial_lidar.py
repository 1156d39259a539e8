"""A new serial LIDAR is a codec, a preset and a link module: nothing in the harness edited.

``toy_lidar/`` (beside this file) is a LIDAR the harness has never heard
of: its own line protocol, beam layout, device profile, link module and
board driver, each made known through the hooks a LIDAR from outside uses
(``kinds.declare``, ``spec.add_preset``, ``profiles.add_profile``). Once
it is imported, `fossbot-hil run --link toylidar` runs a scenario through
it end to end: the harness plays the device on a pty, the toy driver reads
it and publishes /scan, the node under test answers, and the verdicts are
judged on what the node saw.
"""

from __future__ import annotations

import importlib
import json
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

from harness.cli import build_parser, main
from harness.devices.profiles import PROFILES
from harness.lidar.spec import PRESETS
from harness.links import base
from harness.links.kinds import KINDS, device_names, link_kind, node_links, serial_links

pytestmark = [pytest.mark.ros, pytest.mark.timeout(300)]

HERE = Path(__file__).resolve().parent
STUDENT = HERE.parent / "ros" / "student_node.py"
# A wall ahead and a post on the left, closing in: a turned, mirrored or empty board scan
# cannot look like the robot's view, and the warning threshold is crossed.
SCENARIO = (
    "description: A wall ahead and a post on the left, seen by the toy LIDAR.\n"
    "lidar: {preset: toy_lidar}\n"
    "obstacles:\n"
    "  - {type: wall, start: [1.0, -1.0], end: [1.0, 1.0]}\n"
    "  - {type: cylinder, position: [0.0, 0.45], radius: 0.05, height: 0.4}\n"
    "motion: {segments: [{linear: 0.3, until: {duration: 1.5}}]}\n"
)


def _toy_modules() -> list[str]:
    return [name for name in sys.modules if name.split(".")[0] == "toy_lidar"]


@pytest.fixture
def toy_lidar() -> Iterator[ModuleType]:
    """The toy LIDAR, made known for one test only: the other tests of this process see
    the harness's own links."""
    for name in _toy_modules():
        del sys.modules[name]
    module = importlib.import_module("toy_lidar")
    try:
        yield module
    finally:
        KINDS.pop(module.NAME, None)
        base._REGISTRY.pop(module.NAME, None)
        PROFILES.pop(str(module.KIND.device), None)
        PRESETS.pop(module.PRESET, None)
        for name in _toy_modules():
            del sys.modules[name]


@pytest.fixture
def toy_run(toy_lidar: ModuleType, tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """`fossbot-hil run` through the toy LIDAR on a scenario that uses its preset; the
    board driver's process finds the package as the test does."""
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]))
    scenario = tmp_path / "toy_scene.yaml"
    scenario.write_text(SCENARIO)

    def run(*extra: str) -> tuple[int, dict]:
        out = tmp_path / "out"
        code = main(["run", str(scenario), "--link", toy_lidar.NAME, "--out", str(out), *extra])
        return code, json.loads((out / "summary.json").read_text())

    return run


def test_the_new_lidar_is_in_every_list_of_links(toy_lidar: ModuleType) -> None:
    """Declared once, it is a serial link that runs a node, and emulate serves its device."""
    kind = link_kind(toy_lidar.NAME)
    assert kind.serial_line and kind.runs_node
    assert toy_lidar.NAME in serial_links() and toy_lidar.NAME in node_links()
    assert kind.device in device_names()
    parser = build_parser()
    emulate = parser.parse_args(["emulate", str(kind.device), "--scenario", "approach_wall"])
    assert emulate.device == kind.device


def test_a_scenario_runs_through_the_new_lidar(toy_run) -> None:
    """The reference node, behind the toy driver, passes; the scan judged is the board's."""
    code, summary = toy_run()
    assert code == 0, summary
    (only,) = summary["scenarios"]
    assert (only["link"], only["verdict"]) == ("toylidar", "PASS")
    assert only["ticks"] >= 10
    # The node read the device's bytes as the toy driver decoded them: the board's scans
    # show the scene where the robot sees it (an empty or garbled scan cannot be told).
    assert summary["alignment"]["status"] == "aligned", summary["alignment"]


def test_a_wrong_node_fails_through_the_new_lidar(toy_run) -> None:
    """The same run judges: a node that inverts its warning fails it."""
    code, summary = toy_run("--node", f"{sys.executable} {STUDENT} inverted_bool")
    assert code == 1, summary
    assert summary["scenarios"][0]["verdict"] == "FAIL"


def test_the_harness_alone_knows_only_its_own_links() -> None:
    """Without the package imported, the toy LIDAR is nowhere (what the fixture undoes)."""
    assert "toylidar" not in KINDS and "toylidar" not in PROFILES and "toy_lidar" not in PRESETS
