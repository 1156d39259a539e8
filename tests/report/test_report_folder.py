"""The report folder: layout, summary.json, index.html, JUnit properties, atomic files."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from dataclasses import replace
from html.parser import HTMLParser
from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.judge.records import RunResult
from harness.record import read_scans
from harness.report.junit import write_junit
from harness.report.outputs import ArtifactWriter, ReportFolder, artifact_writers, write_report

HOSTILE = '<script>alert("x")</script> & <b>co</b>'


class _Links(HTMLParser):
    """Every href and img src on a page, and its visible text."""

    def __init__(self) -> None:
        super().__init__()
        self.hrefs: list[str] = []
        self.images: list[str] = []
        self.text: list[str] = []
        self.tags: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        values = dict(attrs)
        if tag == "a" and values.get("href"):
            self.hrefs.append(values["href"] or "")
        if tag == "img":
            self.images.append(values.get("src") or "")

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def _files_in(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def test_layout_and_summary_match_the_run(
    tmp_path: Path, passing: RunResult, failing: RunResult
) -> None:
    """One plot and one JSON per scenario; summary.json says what the run said."""
    write_report(tmp_path, [passing, failing])
    assert _files_in(tmp_path) == [
        "index.html",
        "junit.xml",
        "scenarios",
        "scenarios/approach_wall.json",
        "scenarios/approach_wall.mcap",
        "scenarios/approach_wall.png",
        "scenarios/drive_past_10m.json",
        "scenarios/drive_past_10m.mcap",
        "scenarios/drive_past_10m.png",
        "summary.json",
    ]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert (summary["ok"], summary["total"], summary["passed"], summary["failed"]) == (
        False,
        2,
        1,
        1,
    )
    for entry, result in zip(summary["scenarios"], [passing, failing], strict=True):
        assert entry["scenario"] == result.scenario and entry["link"] == "inprocess"
        assert entry["verdict"] == ("PASS" if result.ok else "FAIL")
        assert entry["ticks"] == len(result.records)
        assert entry["warning_when_clear"] == "optional"
        assert entry["failed_ticks"] == [r.tick for r in result.failed_ticks]
        assert entry["failed"] == len(result.failed_ticks)
        assert entry["first_failure"] == result.first_failure
        assert (entry["seed"], entry["threshold"], entry["faults"]) == (0, 0.5, "clean")
        assert entry["wall_s"] == round(result.wall_s, 3)
        name = result.scenario
        assert entry["files"] == {
            "plot": f"scenarios/{name}.png",
            "recording": f"scenarios/{name}.mcap",
            "summary": f"scenarios/{name}.json",
        }
        recording = read_scans(tmp_path / entry["files"]["recording"])
        assert len(recording.scans) == entry["ticks"]
        details = json.loads((tmp_path / entry["files"]["summary"]).read_text())
        assert details["files"] == {
            "plot": f"{name}.png",
            "recording": f"{name}.mcap",
            "summary": f"{name}.json",
        }
        assert len(details["records"]) == entry["ticks"]
        assert [r["tick"] for r in details["records"] if not r["ok"]] == entry["failed_ticks"]
    last = details["records"][-1]
    assert last["claim"]["distance"] == "inf" and last["expected"]["obstacle"] is False


def test_index_links_every_plot_and_escapes_text(
    tmp_path: Path, passing: RunResult, failing: RunResult
) -> None:
    """Every plot is linked and shown; names and explanations from users are only text."""
    hostile = replace(failing, scenario=HOSTILE, records=list(failing.records))
    write_report(tmp_path, [passing, hostile])
    page = (tmp_path / "index.html").read_text()
    links = _Links()
    links.feed(page)
    summary = json.loads((tmp_path / "summary.json").read_text())
    plots = [e["files"]["plot"] for e in summary["scenarios"]]
    assert all((tmp_path / p).is_file() for p in plots)
    assert set(plots) <= set(links.hrefs) and links.images == plots
    assert "script" not in links.tags and "b" not in links.tags
    assert HOSTILE in "".join(links.text)
    assert hostile.first_failure in "".join(links.text)
    assert "&lt;script&gt;" in page and "<script>" not in page
    # The file name is made safe too.
    assert plots[1] == "scenarios/script_alert_x_script_b_co_b.png"


def test_junit_properties_name_the_explanation_and_files(
    tmp_path: Path, passing: RunResult, failing: RunResult
) -> None:
    """Per case: the first failure's explanation and the files, relative to the XML."""
    report = write_report(tmp_path / "report", [passing, failing])
    elsewhere = tmp_path / "ci" / "results.xml"
    write_junit(elsewhere, [passing, failing], artifacts=[s.paths for s in report.scenarios])
    for xml in (tmp_path / "report" / "junit.xml", elsewhere):
        cases = ET.parse(xml).getroot().findall("./testsuite/testcase")
        props = [{p.get("name"): p.get("value") for p in c.iter("property")} for c in cases]
        assert "explanation" not in props[0]
        assert props[1]["explanation"] == failing.first_failure
        assert cases[1].find("failure") is not None
        for p in props:
            for name in ("plot", "recording", "summary"):
                assert (xml.parent / p[name]).resolve().is_file(), p[name]
    assert props[0]["plot"] == "../report/scenarios/approach_wall.png"


def test_scenarios_with_the_same_name_keep_their_own_files(
    tmp_path: Path, passing: RunResult
) -> None:
    """Two scenario files may share a name: the second gets `-2`, nothing is overwritten."""
    report = write_report(tmp_path, [passing, passing])
    plots = [s.paths["plot"].name for s in report.scenarios]
    assert plots == ["approach_wall.png", "approach_wall-2.png"]


def test_a_run_without_ticks_has_no_artifacts(tmp_path: Path) -> None:
    """A scenario that never ran gets its summary entry, and null for each artifact."""
    skipped = RunResult("later", "ros2", 0, 0.0, "", error="not run: ...", not_run=True)
    write_report(tmp_path, [skipped])
    [entry] = json.loads((tmp_path / "summary.json").read_text())["scenarios"]
    assert entry["verdict"] == "NOT RUN"
    assert entry["files"] == {"plot": None, "recording": None, "summary": "scenarios/later.json"}


def _broken_writer(path: Path, result: RunResult) -> Path:
    """Writes half a file, then fails, as a crash in the middle would."""
    path.write_bytes(b"half a recording")
    raise OSError(28, "No space left on device")


def test_writes_are_atomic(tmp_path: Path, passing: RunResult) -> None:
    """A writer failing halfway leaves nothing under its name and no temporary file."""
    writers = [*artifact_writers(), ArtifactWriter("broken", ".bin", _broken_writer)]
    with ReportFolder(tmp_path, writers) as report, pytest.raises(OSError, match="No space left"):
        report.add(passing)
    assert _files_in(tmp_path) == [
        "scenarios",
        "scenarios/approach_wall.mcap",
        "scenarios/approach_wall.png",
    ]
    write_report(tmp_path / "whole", [passing])
    assert not [p for p in (tmp_path / "whole").rglob(".*")]


def test_folder_that_cannot_be_made_is_a_config_error(tmp_path: Path) -> None:
    """A file where the folder should be, or inside its path: one clear error."""
    afile = tmp_path / "report.txt"
    afile.write_text("not a folder")
    with pytest.raises(ConfigError, match="exists and is not a folder"):
        ReportFolder(afile)
    with pytest.raises(ConfigError, match="is a file, not a folder|Not a directory"):
        ReportFolder(afile / "sub")
    assert afile.read_text() == "not a folder"


def test_a_reused_folder_keeps_no_scenario_of_an_earlier_run(
    tmp_path: Path, passing: RunResult, failing: RunResult
) -> None:
    """The earlier run's files (as its summary.json lists them) go; the user's stay, and a
    summary naming files outside scenarios/ deletes nothing there."""
    write_report(tmp_path, [passing, failing])
    before = {p.name for p in (tmp_path / "scenarios").iterdir()}
    (tmp_path / "scenarios" / "notes.txt").write_text("mine")
    (tmp_path / "keep.json").write_text("{}")
    write_report(tmp_path, [passing])
    after = {p.name for p in (tmp_path / "scenarios").iterdir()}
    assert after == {n for n in before if n.startswith(passing.scenario)} | {"notes.txt"}
    summary = json.loads((tmp_path / "summary.json").read_text())
    summary["scenarios"][0]["files"]["plot"] = "keep.json"  # tampered: outside scenarios/
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    write_report(tmp_path, [failing])
    assert (tmp_path / "keep.json").exists() and (tmp_path / "scenarios" / "notes.txt").exists()
