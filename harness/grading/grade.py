"""Grade a class: per student, build, run the suite in a worker process, read the verdicts.

Every step of a student is bounded (build and suite time limits, log size
limits) and runs in a child process, and any failure of one student,
including a bug of ours while grading them, becomes that student's row:
it never stops the others. Each student is one task on a Dask cluster
(harness.cluster: embedded, or the user's), one student per worker at a
time; each suite reserves its own ROS domain on its host, so parallel runs
never hear each other.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shlex
import shutil
import socket
import sys
import threading
import traceback
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from harness.atomic_write import write_atomically
from harness.grading.build import build_student
from harness.grading.class_table import ERROR, NOT_RUN, PASS, StudentGrade
from harness.grading.discover import Student
from harness.grading.hidden import HiddenScenario, scrub_folder
from harness.grading.process import TERM_GRACE_S, Finished, StopFlag, guarded
from harness.grading.scoring import held_of
from harness.grading.warm_judge import Slot, close_judges, drop_judge, warm_judge
from harness.grading.worker import write_job
from harness.judge.records import RunResult
from harness.links.base import LinkOptions
from harness.runner.settings import RunSettings
from harness.sandbox.limits import SandboxLimits
from harness.sandbox.probe import sandbox_problem
from harness.sandbox.refusals import refusal_of
from harness.sandbox.student import sandboxed_run

__all__ = ["GradeConfig", "class_frames", "grade_class", "grade_student"]

MAX_RUN_LOG_BYTES = 20 * 1024 * 1024
WORKER_RETRIES = 1  # a student is graded again once if their worker died under them
STOP_WAIT_S = TERM_GRACE_S + 15.0  # on Ctrl-C: for running students to stop their children
ARTIFACTS = (
    ("report", "report/index.html"),
    ("build log", "build.log"),
    ("run log", "run.log"),
    ("JUnit", "junit.xml"),
)


@dataclass(frozen=True)
class GradeConfig:
    """What every student is graded with."""

    scenarios: tuple[str, ...]  # scenario names, in table order
    scenario_refs: tuple[str, ...]  # what the worker resolves (file paths)
    link: str
    options: LinkOptions  # package and executable set; node and workspace per student
    settings: RunSettings
    students_dir: Path  # <out>/students: one artifact folder per student
    build_timeout: float
    student_timeout: float
    planned: dict[str, int] = field(default_factory=dict)  # scenario -> ticks when unbroken
    hidden: dict[str, HiddenScenario] = field(default_factory=dict)  # scenario -> how shown
    sandbox: SandboxLimits | None = None  # each student's build and run in bubblewrap
    # True: the grader has found that its host can sandbox, and every worker runs there
    # (the embedded cluster), so a worker need not try again before its first student.
    sandbox_checked: bool = False
    # The class's frames as the grader simulated them (harness.runner.frame_memo): every
    # judge starts from them instead of building the worlds for its first student.
    frames: Path | None = None

    @property
    def unheld(self) -> dict[str, tuple[int, int]]:
        """Every scenario's ticks, none held: the row of a student whose suite never ran."""
        return {name: (0, count) for name, count in self.planned.items() if count > 0}

    @property
    def grader_dir(self) -> Path:
        """<out>/grader: what the grader keeps of each student for itself (job, raw results),
        apart from the folder a student may be handed."""
        return self.students_dir.parent / "grader"


def class_frames(grader_dir: Path) -> Path | None:
    """The frames the grader simulated for the tick counts (harness.runner.frame_memo),
    saved in `grader_dir` for every judge to start from, and no longer kept here; None
    if there are none."""
    from harness.runner.frame_memo import remember_frames, save_frames

    grader_dir.mkdir(parents=True, exist_ok=True)
    path = grader_dir / "frames.pickle"
    saved = save_frames(path)
    remember_frames(False)
    return path if saved else None


def _shorten(text: str, folder: Path, command: str | None = None) -> str:
    """Messages name paths relative to the student's artifact folder, a script by its name."""
    if command:
        text = text.replace(command, command.rsplit("/", 1)[-1].strip("'"))
    return text.replace(f"{folder.resolve()}/", "").replace(f"{folder}/", "")


def _placeholder_junit(config: GradeConfig, folder: Path, reason: str) -> None:
    """A JUnit report for a student whose suite never ran: the reason, then NOT RUN."""
    from harness.report.junit import write_junit

    results = [
        RunResult(
            _shown_name(name, config),
            config.link,
            0,
            0.0,
            "",
            error=reason if i == 0 else f"not run: {reason}",
        )
        for i, name in enumerate(config.scenarios)
    ]
    for result in results[1:]:
        result.not_run = True
    write_junit(folder / "junit.xml", results)


def _shown_name(name: str, config: GradeConfig) -> str:
    """A scenario's name as the student's own files give it (a hidden one's label)."""
    hidden = config.hidden.get(name)
    return name if hidden is None else hidden.label


def student_scrub(
    student: Student, config: GradeConfig, folder: Path, also: Sequence[Path] = ()
) -> list[tuple[str, str]]:
    """What the student's own files must not say, and what they say instead: the
    instructor's paths (the class folder, --out, the harness, the Python, `also`: the
    warm judge's slot) and the files of the scenarios (a hidden one by its label)."""
    import harness

    pairs: list[tuple[str, str]] = []
    for where, instead in (
        (student.folder, ""),
        (folder, ""),
        (config.students_dir.parent, ""),
        (Path(harness.__file__).parent.parent, ""),
        *((path, "") for path in also),
    ):
        pairs += [(f"{where}/", instead), (f"{where.resolve()}/", instead)]
    pairs += [(sys.executable, "python3"), (str(Path(sys.executable).resolve()), "python3")]
    for name, ref in zip(config.scenarios, config.scenario_refs, strict=True):
        if Path(ref).is_absolute():
            hidden = config.hidden.get(name)
            pairs.append((ref, Path(ref).name if hidden is None else hidden.label))
    return pairs


def _read_results(path: Path) -> dict[str, Any]:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _unfinished_reason(finished: Finished, config: GradeConfig) -> str:
    if finished.timed_out:
        return f"stopped: the suite took longer than {config.student_timeout:g} s"
    if finished.flooded:
        return f"stopped: the run wrote more than {MAX_RUN_LOG_BYTES // 2**20} MB"
    if finished.cancelled:
        return "interrupted"
    if finished.start_error:
        return finished.start_error
    return f"the test run crashed (exit code {finished.returncode}; see run.log)"


def verdicts_and_failures(
    data: dict[str, Any],
    finished: Finished,
    config: GradeConfig,
    folder: Path,
    command: str | None = None,
) -> tuple[dict[str, str], dict[str, str]]:
    """Each scenario's verdict, and the first failure in words of each that did not pass
    (the run's start error, or how it ended, belongs to the scenario it stopped)."""
    entries = {e.get("scenario"): e for e in data.get("results", []) if isinstance(e, dict)}
    error = data.get("error")
    start_error = str(error) if error and error != "stopped" else None  # "stopped": SIGTERM
    unfinished = not data.get("finished") and start_error is None
    verdicts: dict[str, str] = {}
    failures: dict[str, str] = {}
    if start_error and config.scenarios:  # the suite never began: said on its first scenario
        failures[config.scenarios[0]] = (
            f"node did not start: {_shorten(start_error, folder, command)}"
        )
    for name in config.scenarios:
        entry = entries.get(name)
        if entry is None:
            verdicts[name] = NOT_RUN
            if unfinished:  # the worker was on this scenario when it ended
                unfinished = False
                if not finished.cancelled:
                    verdicts[name] = ERROR
                failures.setdefault(name, f"{name}: {_unfinished_reason(finished, config)}")
            continue
        verdicts[name] = str(entry.get("verdict", ERROR))
        if verdicts[name] in (PASS, NOT_RUN) or name in failures:
            continue
        if entry.get("not_started"):
            why = f"node did not start: {_shorten(str(entry.get('error')), folder, command)}"
        else:
            why = _shorten(str(entry.get("first_failure") or f"{name}: failed"), folder, command)
        failures[name] = why
    return verdicts, failures


def ticks_from(data: dict[str, Any], config: GradeConfig) -> dict[str, tuple[int, int]]:
    """(ticks held, ticks it should have run) of each scenario: a scenario that broke early,
    or never ran, counts its missing ticks as not held (`config.planned`, when known)."""
    held = dict(config.unheld)
    for entry in data.get("results", []):
        if not isinstance(entry, dict) or entry.get("scenario") not in config.scenarios:
            continue
        name = str(entry["scenario"])
        try:
            judged, failed = int(entry.get("ticks", 0)), int(entry.get("failed_ticks", 0))
        except (TypeError, ValueError):
            continue
        counted = held_of(judged, failed, config.planned.get(name, 0))
        if counted is not None:
            held[name] = counted
    return {name: held[name] for name in config.scenarios if name in held}


def node_of(student: Student, config: GradeConfig) -> str:
    """The node this student's suite ran, in words."""
    if student.kind == "script" and student.script is not None:
        return f"{student.script.name} (script)"
    if student.kind in ("package", "workspace"):
        return f"{config.options.package}/{config.options.executable} ({student.kind})"
    return "none"


def _artifacts(folder: Path) -> tuple[tuple[str, str], ...]:
    """(label, path relative to the class table) of the student's files that exist."""
    return tuple(
        (label, f"{folder.parent.name}/{folder.name}/{name}")
        for label, name in ARTIFACTS
        if (folder / name).is_file()
    )


def _run_options(student: Student, config: GradeConfig, folder: Path) -> LinkOptions:
    if student.kind == "script":
        assert student.script is not None
        return _script_options(config, student.script.resolve())
    return replace(config.options, node=None, workspace=str(folder / "colcon"))


def _script_options(config: GradeConfig, script: Path) -> LinkOptions:
    command = f"{shlex.quote(sys.executable)} {shlex.quote(str(script))}"
    return replace(config.options, node=command, package=None, executable=None)


def _script_name(student: Student) -> Path:
    """The node script, relative to the student's folder."""
    assert student.script is not None
    return student.script.resolve().relative_to(student.folder.resolve())


def _slot(config: GradeConfig) -> Slot:
    """This worker's slot for its warm judge, under the grader's folder: named by host,
    process and Dask worker (the embedded cluster's workers are threads of one process)."""
    where = f"{socket.gethostname()}-{os.getpid()}-{_worker_name()}"
    return Slot(config.grader_dir / ".slots" / where)


def _worker_name() -> str:
    """The Dask worker running this task, as a file name ("0" outside a cluster's task)."""
    from distributed import get_worker

    try:
        name = str(get_worker().name)
    except ValueError:  # called directly, not as a task
        return "0"
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


def _judge_warm(job: Path, slot: Slot, config: GradeConfig, cancel: StopFlag) -> Finished:
    """`job` judged by this worker's warm judge (started if need be); a judge stopped
    on the way (time limit, flood, cancel, crash) is not used again."""
    argv = [sys.executable, "-m", "harness.grading.warm_judge"]
    if config.sandbox is not None:  # the node in a nested sandbox that shows slot.node only
        argv = sandboxed_run(
            [*argv, "--sandboxed"],
            node_files=[slot.node],
            scenario_files=[
                *(Path(ref) for ref in config.scenario_refs if Path(ref).is_absolute()),
                *((config.frames,) if config.frames is not None else ()),
            ],
            outputs=[slot.root / "out"],
            limits=config.sandbox,
        )
    judge = warm_judge(guarded(argv), slot.root)
    finished, reusable = judge.judge(
        job,
        slot.student / "run.log",
        timeout=config.student_timeout,
        max_log_bytes=MAX_RUN_LOG_BYTES,
        cancel=cancel,
    )
    if not reusable:
        drop_judge(judge)
    return finished


def _map_results(path: Path, moved: Callable[[str], str]) -> None:
    """The results at `path` with every text `moved` (paths of the slot to the real ones)."""

    def mapped(value: Any) -> Any:
        if isinstance(value, str):
            return moved(value)
        if isinstance(value, list):
            return [mapped(v) for v in value]
        if isinstance(value, dict):
            return {k: mapped(v) for k, v in value.items()}
        return value

    data = _read_results(path)
    if data:
        write_atomically(path, json.dumps(mapped(data), indent=2).encode())


def _grade(student: Student, config: GradeConfig, cancel: StopFlag) -> StudentGrade:
    folder = config.students_dir / student.slug
    grader = config.grader_dir / student.slug  # the grader's own: job, every detail
    for where in (folder, grader):
        shutil.rmtree(where, ignore_errors=True)
        where.mkdir(parents=True)
    not_run = dict.fromkeys(config.scenarios, NOT_RUN)
    artifacts = tuple(
        (label, f"students/{student.slug}/{name}")
        for label, name in ARTIFACTS
        if name != "build.log" or student.kind in ("package", "workspace")
        if label != "report"  # only a suite that ran has one
    )
    node = node_of(student, config)

    def without_run(reason: str, build_s: float | None = None) -> StudentGrade:
        _placeholder_junit(config, folder, reason)
        scrub_folder(folder, student_scrub(student, config, folder))
        failures = {config.scenarios[0]: reason} if config.scenarios else {}
        return StudentGrade(
            student.name,
            student.kind,
            not_run,
            reason,
            artifacts,
            build_s=build_s,
            node=node,
            ticks=config.unheld,
            failures=failures,
        )

    if student.problem is not None:
        return without_run(student.problem)
    if config.sandbox is not None and not config.sandbox_checked and (problem := sandbox_problem()):
        return without_run(f"could not grade: {problem}")  # this worker cannot sandbox
    slot = _slot(config)  # where the worker's warm judge sees this student
    build_s = None
    if student.kind in ("package", "workspace"):
        copy = slot.fill(None, config.students_dir.parent)  # built where the judge sees it
        real = kept = folder / "colcon"
        built = build_student(
            student,
            copy,
            package=config.options.package or "",
            executable=config.options.executable or "",
            log=folder / "build.log",
            timeout=config.build_timeout,
            cancel=cancel,
            sandbox=config.sandbox,
        )
        build_s = built.wall_s
        if not built.ok:
            slot.move_out(folder, grader, kept)
            return without_run(f"did not build: {built.error}", build_s)
        judged = replace(config.options, node=None, workspace=str(copy))
    else:
        copy = slot.fill(student.folder, config.students_dir.parent)
        real, kept = student.folder, None
        judged = _script_options(config, copy / _script_name(student))
    if cancel.is_set():
        slot.move_out(folder, grader, kept)
        return without_run("interrupted", build_s)
    options = _run_options(student, config, folder)  # as the messages name them
    job = write_job(
        slot.grader / "job.json",
        scenarios=list(config.scenario_refs),
        link=config.link,
        options=judged,
        settings=config.settings,
        results=slot.grader / "results.json",
        junit=slot.student / "junit.xml",
        report=slot.student / "report",
        frames=config.frames,
        hidden={
            n: {"label": h.label, "show_failure": h.show_failure} for n, h in config.hidden.items()
        },
    )
    finished = _judge_warm(job, slot, config, cancel)
    slot.move_out(folder, grader, kept)
    _map_results(grader / "results.json", slot.moved(copy, real, folder, grader))
    data = _read_results(grader / "results.json")
    verdicts, failures = verdicts_and_failures(data, finished, config, folder, options.node)
    first = next((failures[n] for n in config.scenarios if n in failures), "")
    refused = None if config.sandbox is None else refusal_of(first, config.sandbox)
    first += f" ({refused})" if refused else ""
    if not (folder / "junit.xml").exists():
        _placeholder_junit(config, folder, first or "no results")
    slotted = (copy if student.kind == "script" else slot.node, slot.student, slot.grader)
    scrub_folder(folder, student_scrub(student, config, folder, (*slotted, slot.root)))
    return StudentGrade(
        student.name,
        student.kind,
        verdicts,
        first,
        _artifacts(folder),
        build_s,
        finished.wall_s,
        ticks=ticks_from(data, config),
        node=node,
        failures=failures,
        notes=_notes(data),
    )


def _notes(data: dict[str, Any]) -> tuple[str, ...]:
    """What the run said once about how the node is wired (e.g. its launch file), in order."""
    notes: list[str] = []
    for entry in data.get("results", []):
        if isinstance(entry, dict):
            notes += [str(n) for n in entry.get("notes") or () if str(n) not in notes]
    return tuple(notes)


def grade_student(
    student: Student, config: GradeConfig, cancel: StopFlag | None = None
) -> StudentGrade:
    """One student's row; a bug of ours while grading them is their row too, not a crash."""
    cancel = cancel or threading.Event()
    try:
        return _grade(student, config, cancel)
    except Exception as err:  # one student must never stop the class
        folder = config.grader_dir / student.slug
        folder.mkdir(parents=True, exist_ok=True)
        write_atomically(folder / "grader-error.log", traceback.format_exc().encode())
        log = f"grader/{student.slug}/grader-error.log"
        reason = f"could not grade: {type(err).__name__}: {err} (see {log})"
        return StudentGrade(
            student.name, student.kind, dict.fromkeys(config.scenarios, NOT_RUN), reason
        )


def grade_class(
    students: Sequence[Student],
    config: GradeConfig,
    client: Any,
    *,
    on_graded: Callable[[Student, StudentGrade, int], None] | None = None,
) -> list[StudentGrade]:
    """Every student's row, in the order given, each graded as a task on `client`'s cluster.

    Students go out only as workers free up (harness.cluster.window), so a worker
    holds only the student it grades. Open the client with ``retries=WORKER_RETRIES``:
    a student whose grading kills its worker runs once more elsewhere (a worker can die
    for reasons of its own) before their row says so. `on_graded` gets each row, with
    how many are being graded; on Ctrl-C or SIGTERM the running builds and suites stop,
    each within its bounded grace, before KeyboardInterrupt goes up.
    """
    from harness.cluster.flag import ClusterFlag
    from harness.cluster.window import Window

    grades: dict[int, StudentGrade] = {}
    stop = ClusterFlag()

    def submit(student: Student) -> Any:
        return client.submit(
            grade_student, student, config, stop, key=_task_key(student), pure=False
        )

    window = Window(client, students, submit)
    try:
        for index, future in window:
            grades[index] = _outcome(future, students[index], config)
            if on_graded is not None:
                on_graded(students[index], grades[index], len(window.running))
    except BaseException:
        with contextlib.suppress(Exception):  # the scheduler may be what went away
            stop.set()
            _wait_for_running(list(window.running), client)
        raise
    finally:
        _close_judges(client, config)
    return [grades[i] for i in range(len(students))]


def _close_judges(client: Any, config: GradeConfig) -> None:
    """Every worker's warm judge closed, its slot and the class's frames gone (an external
    cluster's workers outlive the grading)."""
    with contextlib.suppress(Exception):
        client.run(close_judges, str(config.grader_dir))
    shutil.rmtree(config.grader_dir / ".slots", ignore_errors=True)
    if config.frames is not None:
        config.frames.unlink(missing_ok=True)


def _task_key(student: Student) -> str:
    """Names the student on the dashboard; unique, so a re-graded class is not a cache hit."""
    return f"grade-{student.slug}-{uuid.uuid4().hex[:8]}"


def _outcome(future: Any, student: Student, config: GradeConfig) -> StudentGrade:
    """The task's row; a task Dask gave up on (its worker died every time) is a row too."""
    from distributed import KilledWorker

    try:
        grade = future.result()
    except KilledWorker:
        reason = (
            f"could not grade: the worker grading this student died {WORKER_RETRIES + 1} times "
            "(does the node kill processes other than its own?)"
        )
    except Exception as err:  # lost to the cluster, not to the student's code
        reason = f"could not grade: {type(err).__name__}: {err}"
    else:
        assert isinstance(grade, StudentGrade)
        return grade
    not_run = dict.fromkeys(config.scenarios, NOT_RUN)
    return StudentGrade(student.name, student.kind, not_run, reason)


def _wait_for_running(futures: list[Any], client: Any) -> None:
    """Let the students on the cluster stop their children (each sees the stop flag within
    its bounded grace), then drop whatever is left."""
    from distributed import wait as wait_for

    with contextlib.suppress(Exception):
        wait_for(futures, timeout=STOP_WAIT_S)
    with contextlib.suppress(Exception):
        client.cancel([f for f in futures if not f.done()], reason="interrupted")
