"""One student's scenario suite, as a job the judging process runs (harness.grading.warm_judge).

A student's node can crash, hang or flood its output; running their suite
in the judging process means that can only ever end that process, never the
grader. The job is a JSON file (written by ``grade``) naming the scenarios, the link, the
LinkOptions and RunSettings fields, and where to write ``results.json``, the
JUnit XML and the report folder (what ``fossbot-hil run --out`` writes:
index.html, plots, recordings). ``results.json`` is rewritten (atomically)
after every scenario and the report gets each scenario as it ends, so a run
stopped at its time limit still tells what it judged. The human-readable
account goes to stdout (run.log), as ``fossbot-hil run`` prints it.
"""

from __future__ import annotations

import functools
import json
import signal
import time
from dataclasses import asdict, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from harness.atomic_write import write_atomically
from harness.errors import ConfigError
from harness.links.kinds import ROS2

if TYPE_CHECKING:  # imported by the suite: after the node's fork server has started
    from harness.judge.records import RunResult

__all__ = [
    "interrupt_on_sigterm",
    "link_options_from",
    "not_dumpable",
    "result_entry",
    "run_settings_from",
    "warm_node_server",
    "write_job",
]


def result_entry(result: RunResult) -> dict[str, Any]:
    """What the grader needs of one scenario's run, as JSON-ready data."""
    from harness.judge.verdicts import verdict_of

    return {
        "scenario": result.scenario,
        "verdict": verdict_of(result),
        "first_failure": result.first_failure,
        "error": result.error,
        "not_started": result.not_started,
        "not_run": result.not_run,
        "ticks": len(result.records),
        "failed_ticks": len(result.failed_ticks),
        "wall_s": round(result.wall_s, 3),
        "diagnostics": result.diagnostics,
        "notes": list(result.notes),
    }


def write_job(
    path: Path,
    *,
    scenarios: list[str],
    link: str,
    options: Any,
    settings: Any,
    results: Path,
    junit: Path,
    report: Path | None = None,
    frames: Path | None = None,
    hidden: dict[str, Any] | None = None,
) -> Path:
    """Write a job file for this worker: LinkOptions and RunSettings as their fields;
    `frames`: the class's simulated frames (harness.runner.frame_memo) to start from;
    `hidden`: scenario name -> {"label", "show_failure"}, shown to the student by label."""
    job = {
        "frames": None if frames is None else str(frames),
        "hidden": hidden or {},
        "scenarios": scenarios,
        "link": link,
        "options": asdict(options),
        "settings": asdict(settings),
        "results": str(results),
        "junit": str(junit),
        "report": None if report is None else str(report),
    }
    return write_atomically(path, json.dumps(job, indent=2).encode())


def _write_results(path: Path, entries: list[dict[str, Any]], **state: Any) -> None:
    data = {"results": entries, **state}
    write_atomically(path, json.dumps(data, indent=2).encode())


def link_options_from(data: dict[str, Any]) -> Any:
    """The LinkOptions `write_job` wrote, as they were: JSON made each tuple a list
    (params, launch, topic_params, board_commands) and the LIDAR mount a dict."""
    from harness.lidar.mount import LidarMount
    from harness.links.base import LinkOptions

    known = {f.name for f in fields(LinkOptions)}
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items() if k in known}
    if isinstance(values.get("lidar_mount"), dict):
        values["lidar_mount"] = LidarMount(**values["lidar_mount"])
    return LinkOptions(**values)


def run_settings_from(data: dict[str, Any]) -> Any:
    from harness.runner.settings import RunSettings

    known = {f.name for f in fields(RunSettings)}
    return RunSettings(**{k: v for k, v in data.items() if k in known})


def run_job(job: dict[str, Any]) -> int:
    """Run the job's suite; results.json tells the outcome, the exit code only if it broke."""
    from harness.report.outputs import ReportFolder

    report = ReportFolder(job["report"]) if job.get("report") else None
    suite = _Suite(job, report)
    started = time.monotonic()
    try:
        return suite.run()
    finally:
        if report is not None:
            report.finish(time.monotonic() - started)  # index.html of what was judged


class _Suite:
    """One student's suite: each result kept (results.json, JUnit, report) as it ends."""

    def __init__(self, job: dict[str, Any], report: Any) -> None:
        self.job = job
        self.report = report
        self.results_path = Path(job["results"])
        self.entries: list[dict[str, Any]] = []
        self.results: list[RunResult] = []
        self.scenarios: dict[str, Any] = {}
        self.hidden = _hidden_scenarios(job.get("hidden") or {})

    def shown(self, result: RunResult) -> RunResult:
        """`result` as the student's own files show it (a hidden scenario: label, verdict)."""
        from harness.grading.hidden import hidden_run

        hidden = self.hidden.get(result.scenario)
        return result if hidden is None else hidden_run(result, hidden)

    def keep(self, result: RunResult) -> None:
        from harness.report.junit import write_junit

        shown = self.shown(result)
        self.results.append(shown)
        self.entries.append(result_entry(result))  # the grader's own: every detail
        _write_results(self.results_path, self.entries, finished=False, error=None)
        write_junit(self.job["junit"], self.results)  # a run stopped later keeps its report
        if self.report is not None:
            hidden = shown is not result
            self.report.add(shown, None if hidden else self.scenarios.get(result.scenario))
        count = "" if shown is not result else f" ({len(result.records)} ticks)"
        print(f"{shown.scenario}: judged{count}", flush=True)

    def run(self) -> int:
        from rich.console import Console

        from harness.report.terminal import print_results
        from harness.runner.suite import run_suite

        job = self.job
        try:
            chosen = [_scenario(ref) for ref in job["scenarios"]]
            if job.get("frames"):
                _frames_given(job["frames"], tuple(job["scenarios"]))
            self.scenarios.update((s.name, s) for s in chosen)
            run_suite(
                chosen,
                job["link"],
                link_options_from(job["options"]),
                run_settings_from(job["settings"]),
                on_result=self.keep,
            )
        except ConfigError as err:  # e.g. the node command cannot be resolved
            _write_results(self.results_path, self.entries, finished=False, error=str(err))
            print(f"error: {err}", flush=True)
            return 0
        except KeyboardInterrupt:  # SIGTERM from the grader: links are closed, nodes stopped
            _write_results(self.results_path, self.entries, finished=False, error="stopped")
            return 1
        _write_results(self.results_path, self.entries, finished=True, error=None)
        print(flush=True)
        console = Console(highlight=False, width=160, force_terminal=False)
        print_results(console, self.results)  # the verdicts, once, with the failures explained
        return 0


@functools.cache
def _scenario(ref: str) -> Any:
    """A scenario read and checked once a process: a warm judge's students share them (a
    class's scenario files do not change while it is graded; a Scenario is frozen)."""
    from harness.scenario.files import resolve_scenario

    return resolve_scenario(ref)


@functools.cache
def _frames_given(path: str, refs: tuple[str, ...]) -> int:
    """The grader's frames of these scenarios kept here, once a process (a warm judge's
    first student): how many plans (none where the memo is off or the file unreadable)."""
    from harness.runner.frame_memo import load_frames

    return load_frames(Path(path), [_scenario(ref) for ref in refs])


def _hidden_scenarios(data: dict[str, Any]) -> dict[str, Any]:
    from harness.grading.hidden import HiddenScenario

    return {
        str(name): HiddenScenario(str(how["label"]), bool(how.get("show_failure")))
        for name, how in data.items()
    }


def not_dumpable() -> None:
    """In a sandbox: the node shares this process's PIDs, so keep it out of this process's
    /proc entries (its open files, its root, its memory: the scenario files)."""
    import ctypes

    PR_SET_DUMPABLE = 4
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_DUMPABLE, 0, 0, 0, 0)


def interrupt_on_sigterm() -> None:
    def handler(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, handler)


def warm_node_server(job: dict[str, Any]) -> bool:
    """Start the fork server students' nodes start from (``warm_python``) now, before
    this process imports the runner: its imports (rclpy, the messages) then run beside
    ours instead of after them. Only for a node the ros2 link starts; True if started.
    The suite uses this server (one per process and module) and closes it at its end."""
    from harness.nodes.forkserver import shared
    from harness.nodes.process import fork_server_enabled
    from harness.nodes.python_script import SERVER_MODULE

    if job.get("link") != ROS2 or not fork_server_enabled():
        return False
    shared(SERVER_MODULE)  # in the sandbox: started in the node's nested one, as later
    return True
