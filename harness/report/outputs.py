"""The report folder (`fossbot-hil run --out DIR`, docs/reports.md): per-scenario files,
then the run's.

Adding a kind of per-scenario file is one entry in ``artifact_writers``.
Every file lands atomically, so an interrupted run never leaves half a file
under its final name; paths inside a report file are relative to its
folder, so the folder can be moved or archived whole.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from harness.atomic_write import fill_atomically, relative_path, write_atomically
from harness.errors import ConfigError
from harness.judge.records import RunResult
from harness.report.folder_lock import lock_folder
from harness.report.previous_run import clear_previous_run
from harness.report.summary import (
    coverage_entry,
    json_bytes,
    run_summary,
    scenario_details,
    scenario_entry,
)
from harness.safe_text import DIAGNOSTICS_LIMIT, for_storage

if TYPE_CHECKING:  # pydantic only when a scenario is at hand
    from harness.judge.alignment import Alignment
    from harness.report.baseline import Baseline
    from harness.scenario.schema import Scenario

__all__ = [
    "ArtifactWriter", "ReportFolder", "ScenarioFiles",
    "WorldArtifactWriter", "artifact_writers", "prepare_folder", "write_report",
]  # fmt: skip

SCENARIO_FOLDER = "scenarios"
SUMMARY, JUNIT, INDEX = "summary.json", "junit.xml", "index.html"
DETAILS = "summary"  # the name of each scenario's own JSON file in `files`


@dataclass(frozen=True)
class ArtifactWriter:
    """One kind of per-scenario file: `write` must write `path` and return it."""

    name: str  # key in summary.json's `files` and a JUnit property name
    suffix: str  # file name = <scenario><suffix>
    write: Callable[[Path, RunResult], Path]


@dataclass(frozen=True)
class WorldArtifactWriter:
    """A per-scenario file drawn from the run and its scenario (the world it ran in):
    `write(path, result, scenario)`; not written for a result added without its scenario."""

    name: str
    suffix: str
    write: Callable[[Path, RunResult, Scenario], Path]


Writer = ArtifactWriter | WorldArtifactWriter


def _write_plot(path: Path, result: RunResult) -> Path:
    from harness.report.plot import write_plot  # numpy now, matplotlib only when drawing

    return write_plot(path, result)


def artifact_writers(*, animate: bool = False) -> list[Writer]:
    """The per-scenario artifacts, in the order they are written; `animate` adds the
    animated top-down view (`--animate`: seconds per scenario, so last and optional)."""
    writers: list[Writer] = [
        ArtifactWriter("plot", ".png", _write_plot),
        ArtifactWriter("recording", ".mcap", _write_recording),
    ]
    if animate:
        writers.append(WorldArtifactWriter("animation", ".gif", _write_animation))
    return writers


def _write_animation(path: Path, result: RunResult, scenario: Scenario) -> Path:
    from harness.report.animation import write_animation  # matplotlib only when drawing

    return write_animation(result, scenario, path)


def _write_recording(path: Path, result: RunResult) -> Path:
    from harness.record import write_recording  # mcap and rosbags only when recording

    return write_recording(path, result)


def prepare_folder(path: str | Path) -> Path:
    """Create the report folder now, before anything runs (a ConfigError if it cannot)."""
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise ConfigError(f"{path}: exists and is not a folder")
    try:
        (folder / SCENARIO_FOLDER).mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise ConfigError(f"{path}: a part of this path is a file, not a folder") from None
    except OSError as err:
        raise ConfigError(f"{path}: cannot create the folder: {err.strerror or err}") from None
    for where in (folder, folder / SCENARIO_FOLDER):
        if not os.access(where, os.W_OK | os.X_OK):
            raise ConfigError(f"{path}: folder is not writable")
    return folder


def safe_stem(name: str) -> str:
    """A scenario name as a portable file name (letters, digits, . _ -)."""
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._")
    return stem[:100] or "scenario"


def _write_via_temporary(
    writer: Writer, final: Path, result: RunResult, scenario: Scenario | None
) -> Path | None:
    """Run `writer` on a hidden temporary file, then rename it to `final`; None for a
    world writer without its scenario."""
    if isinstance(writer, ArtifactWriter):
        write = writer.write
        return fill_atomically(
            final, lambda temporary: write(temporary, result), suffix=writer.suffix
        )
    if scenario is None:
        return None
    draw = writer.write
    return fill_atomically(
        final, lambda temporary: draw(temporary, result, scenario), suffix=writer.suffix
    )


def stored(result: RunResult) -> RunResult:
    """`result` as report files keep it: the run's own texts, from the node too, bounded
    and storable as UTF-8 (tick records are bounded when judged)."""
    return replace(
        result,
        scenario=for_storage(result.scenario),
        error=None if result.error is None else for_storage(result.error),
        diagnostics=for_storage(result.diagnostics, DIAGNOSTICS_LIMIT),
    )


@dataclass
class ScenarioFiles:
    """What was written for one scenario: artifact name -> absolute path."""

    result: RunResult
    paths: dict[str, Path] = field(default_factory=dict)


class ReportFolder:
    """Fills a report folder, locked until `finish` or `close`: `add` each result as it
    finishes (a later scenario that hangs keeps the earlier plots), then `finish`."""

    def __init__(self, root: str | Path, writers: Sequence[Writer] | None = None) -> None:
        self.root = prepare_folder(root)
        self._lock = lock_folder(self.root, root)
        self.cleared = clear_previous_run(self.root)  # an earlier run's files, once locked
        self.writers = list(writers) if writers is not None else artifact_writers()
        self.scenarios: list[ScenarioFiles] = []
        self._stems: set[str] = set()

    def _stem(self, scenario: str) -> str:
        """A file stem no earlier scenario of this run took (names may repeat)."""
        base = safe_stem(scenario)
        stem, n = base, 1
        while stem.lower() in self._stems:
            n += 1
            stem = f"{base}-{n}"
        self._stems.add(stem.lower())
        return stem

    def add(self, result: RunResult, scenario: Scenario | None = None) -> ScenarioFiles:
        """Write this scenario's artifacts (none without ticks) and its JSON; `scenario`,
        the one `result` ran, for the writers that draw its world."""
        folder = self.root / SCENARIO_FOLDER
        result = stored(result)
        stem = self._stem(result.scenario)
        files = ScenarioFiles(result)
        if result.records:
            for writer in self.writers:
                final = folder / f"{stem}{writer.suffix}"
                written = _write_via_temporary(writer, final, result, scenario)
                if written is not None:
                    files.paths[writer.name] = written
        details = folder / f"{stem}.json"
        files.paths[DETAILS] = details
        names = self._names(files, relative_to=folder)
        write_atomically(details, json_bytes(scenario_details(result, names)))
        self.scenarios.append(files)
        return files

    def _names(self, files: ScenarioFiles, *, relative_to: Path) -> dict[str, str | None]:
        """Every artifact name (None where not written) -> path relative to a folder."""
        names: dict[str, str | None] = {w.name: None for w in self.writers}
        for name, path in files.paths.items():
            names[name] = relative_path(path, relative_to)
        return names

    def finish(
        self,
        wall_s: float | None = None,
        *,
        baseline: Baseline | None = None,
        alignment: Alignment | None = None,
        alignment_mode: str = "warn",
    ) -> Path:
        """Write summary.json, junit.xml and index.html (with the `--baseline` comparison and
        the board's /scan `alignment` when given); return the index page."""
        from harness.report.html import index_html
        from harness.report.junit import junit_xml

        done = self.scenarios
        results = [s.result for s in done]
        entries = [scenario_entry(s.result, self._names(s, relative_to=self.root)) for s in done]
        summary = run_summary(
            entries,
            wall_s,
            alignment=alignment,
            alignment_mode=alignment_mode,
            coverage=coverage_entry(results),
        )
        if baseline is not None:
            from harness.report.baseline import compare, with_comparison

            summary = with_comparison(summary, compare(baseline, entries))
        write_atomically(self.root / SUMMARY, json_bytes(summary))
        xml = junit_xml(results, artifacts=[s.paths for s in done], base=self.root)
        write_atomically(self.root / JUNIT, xml)
        page = index_html(summary, diagnostics=[s.result.diagnostics for s in done])
        index = write_atomically(self.root / INDEX, page)
        self.close()  # the report is complete: the folder is the next run's
        return index

    def close(self) -> None:
        """Unlock the folder (`finish` does); safe to call twice."""
        self._lock.release()

    def __enter__(self) -> ReportFolder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def write_report(
    root: str | Path,
    results: Sequence[RunResult],
    writers: Sequence[Writer] | None = None,
    scenarios: Sequence[Scenario | None] = (),
) -> ReportFolder:
    """The whole folder for results already at hand (the CLI adds them one by one);
    `scenarios[i]`, when given, is the one `results[i]` ran."""
    with ReportFolder(root, writers) as report:
        for i, result in enumerate(results):
            report.add(result, scenarios[i] if i < len(scenarios) else None)
        report.finish()
    return report
