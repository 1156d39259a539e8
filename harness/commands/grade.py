"""`fossbot-hil grade DIR...`: build and test each student's node; write the class table.

Exit 0 once every student is graded (their failures are the output, not
an error), 2 for bad input. The rules for what counts as a student, and the
output folder's layout, are in docs/grading.md.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import importlib.util
import json
import shutil
import time
from pathlib import Path
from typing import TYPE_CHECKING

from rich.console import Console

from harness.commands.arguments import (
    add_judging_options,
    add_link_option,
    add_node_options,
    add_scenario_overrides,
    check_status_regex,
    duration,
    judging_settings,
    link_options,
    not_empty,
    request_of,
)
from harness.commands.cluster_options import add_cluster_options, describe_cluster, workers
from harness.commands.sandbox_options import add_sandbox_options, check_workers, sandbox_limits
from harness.errors import ConfigError
from harness.grading import LAB_EXECUTABLE, LAB_PACKAGE
from harness.grading.discover import GRADES_MARKER, Student, absolute
from harness.holder_lock import HolderLock
from harness.links.kinds import node_links
from harness.report.folder_lock import lock_folder

if TYPE_CHECKING:  # imported when grading starts (the parser is built for any command)
    from harness.grading.class_table import StudentGrade
    from harness.grading.grade import GradeConfig
    from harness.grading.grading_file import GradebookSettings, GradingFile
    from harness.grading.roster import Roster
    from harness.grading.scoring import ScorePlan
    from harness.run_request import RunRequest
    from harness.scenario.schema import Scenario

NAME = "grade"
HELP = "build and test every student's node in DIR; write the class table (CSV, HTML)"

NODE_LINKS = node_links()  # the links that start a node
NOT_FOR_GRADING = {
    "node": "each student's node comes from their folder",
    "workspace": "each student's folder is built into --out",
    "domain_id": "each student's run reserves a free ROS domain id",
    "ros_network": "students are graded on this machine only",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "dirs",
        nargs="+",
        metavar="DIR",
        help="folder with one folder per student (or one student's workspace or package)",
    )
    parser.add_argument(
        "--out",
        type=not_empty,
        default="grades",
        metavar="DIR",
        help="where the class table and each student's logs go (default: grades)",
    )
    parser.add_argument(  # the name before grading ran on Dask; kept so scripts still work
        "--jobs", dest="workers", type=workers, help=argparse.SUPPRESS
    )
    parser.add_argument(
        "--scenario",
        action="append",
        default=[],
        metavar="NAME[,NAME]",
        help="scenario name or file (repeatable; default: all shipped, or the grading file's)",
    )
    parser.add_argument(
        "--grading",
        type=not_empty,
        metavar="FILE",
        help="grading file (YAML): scenarios, weights, hidden scenarios, points and judging "
        "options; options typed on the command line win (see docs/grading.md)",
    )
    parser.add_argument(
        "--roster",
        type=not_empty,
        metavar="CSV",
        help="class roster with columns folder,id[,name]: ids in the tables and the "
        "gradebook, a row for every student on it",
    )
    parser.add_argument(
        "--gradescope",
        action="store_true",
        help="also write each student's Gradescope results.json "
        "(students/<name>/gradescope/results.json)",
    )
    add_link_option(parser)
    add_scenario_overrides(parser)
    add_judging_options(parser)
    parser.add_argument(
        "--build-timeout",
        type=duration("build timeout"),
        default=180.0,
        metavar="S",
        help="longest one student's colcon build may take (default 180)",
    )
    parser.add_argument(
        "--student-timeout",
        type=duration("student timeout"),
        default=900.0,
        metavar="S",
        help="longest one student's scenario suite may take (default 900)",
    )
    parser.add_argument(
        "--no-audit",
        action="store_true",
        help="do not check which typical mistakes the scenarios let pass (an audit of the "
        "scenarios runs once after the class and is kept in the user's cache; see "
        "fossbot-hil audit)",
    )
    add_cluster_options(parser, unit="students")
    add_sandbox_options(parser)
    add_node_options(parser)
    _adapt_node_options(parser)


def _adapt_node_options(parser: argparse.ArgumentParser) -> None:
    """`run`'s link and node options: the lab's names as defaults, the refused ones hidden."""
    parser.set_defaults(package=LAB_PACKAGE, executable=LAB_EXECUTABLE)
    for action in parser._actions:  # argparse has no public way to edit an added option
        if action.dest in NOT_FOR_GRADING:
            action.help = argparse.SUPPRESS
        elif action.dest == "link":
            action.help = "ros2 (default), or a virtual board: rplidar, ldlidar"
        elif action.dest in ("package", "executable"):
            action.help = f"{action.help} (default: {action.default})"
    for group in parser._action_groups:
        if group.title and group.title.startswith("node under test"):
            group.title = "each student's node"


def check_grading_options(args: argparse.Namespace, request: RunRequest) -> None:
    """Options `run` takes that make no sense for a class are mistakes, not ignored."""
    for name, why in NOT_FOR_GRADING.items():
        if getattr(args, name):
            raise ConfigError(f"--{name.replace('_', '-')} does not apply to grade: {why}")
    if request.link not in NODE_LINKS:
        known = ", ".join(NODE_LINKS)
        raise ConfigError(f"--link {request.link}: grade runs students' nodes (use {known})")
    if not request.package or not request.executable:
        raise ConfigError("--package and --executable must name the lab's node")


def selected_scenarios(items: list[str]) -> list[Scenario]:
    """`--scenario` items (comma lists allowed), all resolved now, relative to where the
    command was given; default every shipped one."""
    from harness.scenario.files import resolve_scenario, shipped_scenarios

    names = [n.strip() for item in items for n in item.split(",") if n.strip()]
    scenarios = [resolve_scenario(n) for n in names] if names else shipped_scenarios()
    return _distinct(scenarios)


def _distinct(scenarios: list[Scenario]) -> list[Scenario]:
    """The scenarios, each file made absolute (workers run in each student's folder); a name
    given twice is a mistake."""
    seen: set[str] = set()
    for s in scenarios:
        if s.name in seen:
            raise ConfigError(f"--scenario {s.name}: given twice")
        seen.add(s.name)
    return [
        s.model_copy(update={"source": str(Path(s.source).resolve())}) if s.source else s
        for s in scenarios
    ]


def apply_grading_file(args: argparse.Namespace) -> GradingFile | None:
    """The grading file of --grading, its options under the typed ones (``args.under``, which
    `request_of` reads); None without one. Its scenarios replace --scenario (both given: a
    usage error)."""
    from harness.grading.grading_file import load_grading_file

    if not args.grading:
        return None
    grading = load_grading_file(args.grading)
    if args.scenario:
        raise ConfigError(
            f"--scenario and --grading {args.grading}: the grading file lists the scenarios "
            "(give one of them)"
        )
    args.under = grading.request_values()
    return grading


def graded_scenarios(
    args: argparse.Namespace, grading: GradingFile | None
) -> tuple[list[Scenario], ScorePlan]:
    """The scenarios, resolved now, and how they are scored and shown."""
    from harness.grading.scoring import ScorePlan
    from harness.scenario.files import resolve_scenario

    if grading is None:
        scenarios = selected_scenarios(args.scenario)
        return scenarios, ScorePlan.equal([s.name for s in scenarios])
    scenarios = _distinct([resolve_scenario(p.scenario) for p in grading.planned])
    plan = grading.score_plan([s.name for s in scenarios])
    return scenarios, plan


def check_out(out: Path) -> None:
    """The output folder must be new, empty or one of ours: never someone's folder of files."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out}: not a folder")
    if out.is_dir() and not (out / GRADES_MARKER).exists() and any(out.iterdir()):
        raise ConfigError(
            f"--out {out}: not empty and not written by 'fossbot-hil grade' "
            "(choose a new or empty folder)"
        )


def prepare_out(out: Path) -> HolderLock:
    """Create (or reuse) the output folder, marked as ours, without last time's students;
    locked first (report.folder_lock): a second grade or run into it is refused until the
    returned lock is released."""
    check_out(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ConfigError(f"--out {out}: {err.strerror or err}") from None
    lock = lock_folder(out, f"--out {out}")
    try:
        (out / GRADES_MARKER).write_text("written by fossbot-hil grade\n", encoding="utf-8")
    except OSError as err:
        lock.release()
        raise ConfigError(f"--out {out}: {err.strerror or err}") from None
    _set_aside(out, ("students", "grader", "unpacked"))  # last time's students, their archives
    return lock


REPLACED_PREFIX = ".replaced-"  # last time's folders, moved aside while they are removed


def _set_aside(out: Path, names: tuple[str, ...]) -> None:
    """Move the `names` in `out` aside at once and remove them in the background (a class's
    reports take a while to delete); what an earlier grade left aside goes with them."""
    import threading
    import uuid

    aside = out / f"{REPLACED_PREFIX}{uuid.uuid4().hex[:8]}"
    doomed = [p for p in out.glob(f"{REPLACED_PREFIX}*") if p.is_dir()]
    for name in names:
        if (out / name).exists():
            aside.mkdir(exist_ok=True)
            (out / name).rename(aside / name)
    doomed += [aside] if aside.is_dir() else []

    def remove() -> None:
        for folder in doomed:
            shutil.rmtree(folder, ignore_errors=True)

    if doomed:
        threading.Thread(target=remove, name="fossbot-hil-set-aside", daemon=True).start()


def _graded_line(student: Student, grade: StudentGrade) -> str:
    """One line per student as their row comes in."""
    from harness.safe_text import for_terminal

    parts = [student.kind]
    if grade.build_s is not None:
        built = not grade.first_failure.startswith("did not build")
        parts.append(f"{'built' if built else 'build failed'} in {grade.build_s:.1f} s")
    if grade.run_s is not None:
        held = f" ({grade.ticks_held} ticks held)" if grade.ticks_held else ""
        parts.append(f"{grade.score} passed{held} in {grade.run_s:.1f} s")
    else:
        parts.append("not run")
    name = for_terminal(student.name)  # a folder name is the student's choice
    return f"  {name}: {', '.join(parts)}"


def _all_passed(grade: StudentGrade) -> bool:
    from harness.grading.class_table import PASS

    return bool(grade.verdicts) and all(v == PASS for v in grade.verdicts.values())


def run(args: argparse.Namespace, console: Console) -> int:
    from harness.atomic_write import write_atomically
    from harness.cluster.client import check_cluster_options, dashboard
    from harness.cluster.progress import add_task, task_progress
    from harness.cluster.soon import client_soon
    from harness.commands.grade_audit import class_audit
    from harness.grading.build import colcon_executable
    from harness.grading.class_table import (
        class_csv,
        class_html,
        class_rich_table,
        scenario_legend,
    )
    from harness.grading.discover import discover
    from harness.grading.grade import WORKER_RETRIES, GradeConfig, class_frames, grade_class
    from harness.grading.grading_file import GradebookSettings
    from harness.grading.hidden import HiddenScenario
    from harness.grading.roster import load_roster
    from harness.runner.frame_memo import remember_frames
    from harness.runner.planned_ticks import planned_ticks
    from harness.runner.settings import check_settings

    grading = apply_grading_file(args)  # its options count as typed where none was
    request = request_of(args, check=False)
    check_grading_options(args, request)
    check_cluster_options(args.scheduler, args.workers)
    options = link_options(args)  # topics and parameters: refused now, before any folder
    scenarios, plan = graded_scenarios(args, grading)
    settings = judging_settings(args)
    check_settings(scenarios, settings)  # a bad --faults or --threshold: a usage error now
    check_status_regex(args)
    roster = load_roster(args.roster) if args.roster else None
    out = Path(args.out)
    found = discover(args.dirs, exclude=out)  # before prepare_out: no folder for a typo
    check_out(out)
    with contextlib.ExitStack() as stack:
        # The cluster starts now, in the background, while the checks below and the
        # scenarios' tick counts run here (harness.cluster.soon).
        soon = stack.enter_context(
            client_soon(
                scheduler=args.scheduler,
                workers=args.workers,
                retries=WORKER_RETRIES,
                worker_wait=args.worker_wait,
                preload=("harness.grading.grade",),  # what a worker process imports first
                # A sandboxed student cannot reach the grader's processes (PID namespace),
                # so the embedded workers can be its threads; --no-sandbox keeps processes,
                # so a node that kills its worker costs that worker, not the class.
                threads=not args.no_sandbox,
            )
        )
        if any(s.kind in ("package", "workspace") for s in found.students):
            colcon_executable()
        if importlib.util.find_spec("rclpy") is None:  # checked last: the input was fine
            raise ConfigError(
                "grading needs rclpy: pip install 'fossbot-hil[ros]' (or source ROS 2 Jazzy)"
            )
        sandbox = sandbox_limits(args, console)  # this machine cannot sandbox: exit 2 now
        remember_frames()  # the tick counts' frames are the judges' too (class_frames below)
        stack.callback(remember_frames, False)  # and none kept here if grade ends before
        planned = planned_ticks(scenarios, settings)  # what a partial score counts against
        replaced = previous_grading(out)
        client = soon.client()  # a --scheduler that does not answer: exit 2 now
        if sandbox is not None and args.scheduler:
            check_workers(client, console)  # the embedded cluster's are this machine's
        stack.enter_context(prepare_out(out))  # the folder is this grade's until it is done
        from harness.grading.archives import UNPACKED, unpack_submissions

        found.students = unpack_submissions(found, out / UNPACKED)  # now that --out is ours
        found.students = [absolute(s) for s in found.students]  # workers run elsewhere
        if any(s.kind in ("package", "workspace") for s in found.students):
            colcon_executable()  # an archive may hold the class's first package
        names = tuple(s.name for s in scenarios)
        config = GradeConfig(
            scenarios=names,
            scenario_refs=tuple(s.source or s.name for s in scenarios),
            link=request.link,
            options=options,
            settings=settings,
            students_dir=out.resolve() / "students",  # workers run in their student's folder
            build_timeout=args.build_timeout,
            student_timeout=args.student_timeout,
            planned=planned,
            hidden={
                s.name: HiddenScenario(s.label, s.show_failure) for s in plan.scenarios if s.hidden
            },
            sandbox=sandbox,
            sandbox_checked=args.scheduler is None,  # the embedded cluster's host is this one
            frames=class_frames(out.resolve() / "grader"),
        )
        if replaced:
            console.print(replaced, markup=False, highlight=False)
        for note in found.skipped:
            console.print(f"skipped {note}", markup=False, highlight=False)
        count = len(found.students)
        console.print(
            f"grading {count} student{'s' if count != 1 else ''} on {len(names)} scenario"
            f"{'s' if len(names) != 1 else ''} over {request.link} "
            f"{describe_cluster(args.scheduler, args.workers)}, into {out}",
            markup=False,
            highlight=False,
        )
        if sandbox is not None:
            console.print(
                f"each student in a bubblewrap sandbox: {sandbox.describe()} "
                "(--sandbox-memory, --sandbox-processes)",
                markup=False,
                highlight=False,
            )
        address = dashboard(client)
        if address:
            console.print(f"Dask dashboard: {address}", markup=False, highlight=False)
        started = time.monotonic()
        with task_progress(console, "students", failed="not all passed") as progress:
            bar = add_task(progress, "students", count)
            failed = 0

            def graded(student: Student, grade: StudentGrade, running: int) -> None:
                nonlocal failed
                failed += not _all_passed(grade)
                progress.console.print(_graded_line(student, grade), markup=False, highlight=False)
                progress.update(bar, advance=1, running=running, failed=failed)

            grades = grade_class(found.students, config, client, on_graded=graded)
        wall_s = time.monotonic() - started
        _write_gradescope(found.students, grades, plan, out, enabled=args.gradescope)
        grades = scored_rows(grades, plan, roster, config, console)
        audit_line = None if args.no_audit else class_audit(console, client, scenarios, config, out)
        meta = [
            ("scenarios", ", ".join(names)),
            ("score", _score_words(plan)),
            ("link", request.link),
            ("package students", f"{request.package}/{request.executable}"),
            ("seed", "per scenario" if request.seed is None else str(request.seed)),
            (
                "threshold",
                "per scenario" if request.threshold is None else f"{request.threshold:g} m",
            ),
            ("warning when clear", request.warning_when_clear or "per scenario (optional)"),
            ("graded", time.strftime("%Y-%m-%d %H:%M")),
        ]
        csv_path = write_atomically(
            out / "grades.csv", class_csv(grades, names, roster=roster is not None)
        )
        html_path = write_atomically(
            out / "grades.html",
            class_html(grades, names, meta=meta, max_score=plan.max_score, audit=audit_line),
        )
        book = grading.gradebook if grading is not None else GradebookSettings()
        book_path = write_atomically(
            out / GRADEBOOK, _gradebook(grades, plan, book, rostered=roster is not None)
        )
        console.print()
        console.print(class_rich_table(grades, names, width=console.width))
        console.print(scenario_legend(names), markup=False, highlight=False)
        console.print()
        console.print(
            f"graded {count} in {wall_s:.1f} s; wrote {csv_path}, {html_path} and {book_path}",
            markup=False,
            highlight=False,
        )
        if audit_line:  # one line, however long: scripts look for it
            console.print(audit_line, markup=False, highlight=False, soft_wrap=True)
        return 0


GRADEBOOK = "gradebook.csv"


def previous_grading(out: Path) -> str | None:
    """What grading into `out` replaces, in words (None: nothing of ours is there)."""
    table = out / "grades.csv"
    if not (out / GRADES_MARKER).exists() or not table.is_file():
        return None
    try:
        with open(table, encoding="utf-8", newline="") as handle:  # cells may hold newlines
            rows = max(0, sum(1 for _ in csv.reader(handle)) - 1)
        when = time.strftime("%Y-%m-%d %H:%M", time.localtime(table.stat().st_mtime))
    except (OSError, UnicodeDecodeError, csv.Error):
        return f"replacing the earlier grading in {out}"
    return f"replacing the grading of {rows} student{'s' if rows != 1 else ''} from {when} in {out}"


def _score_words(plan: ScorePlan) -> str:
    from harness.grading.scoring import points_text

    weights = ", ".join(
        f"{s.shown_name if s.hidden else s.name} {points_text(plan.max_points(s.name))}"
        for s in plan.scenarios
    )
    partial = "; partial credit by ticks held" if plan.partial_credit else ""
    return f"of {points_text(plan.max_score)} ({weights}){partial}"


def scored_rows(
    grades: list[StudentGrade],
    plan: ScorePlan,
    roster: Roster | None,
    config: GradeConfig,
    console: Console,
) -> list[StudentGrade]:
    """Every row with its score; with a roster, its id and name, and a row for each
    student on the roster who handed nothing in."""
    from dataclasses import replace

    from harness.grading.class_table import NOT_RUN, StudentGrade
    from harness.safe_text import for_terminal

    rows = [replace(g, points=plan.score(g.verdicts, g.ticks)) for g in grades]
    if roster is None:
        return rows
    matched: set[str] = set()
    named, unknown = [], []
    for g in rows:
        entry = roster.entry_for(g.name)
        if entry is None:
            unknown.append(g.name)
            named.append(g)
            continue
        matched.add(entry.folder.casefold())
        named.append(replace(g, student_id=entry.id, full_name=entry.name))
    for entry in roster.entries:
        if entry.folder.casefold() not in matched:
            named.append(
                StudentGrade(
                    entry.folder,
                    "none",
                    dict.fromkeys(config.scenarios, NOT_RUN),
                    "no submission",
                    ticks=config.unheld,
                    points=0.0,
                    student_id=entry.id,
                    full_name=entry.name,
                )
            )
    missing = len(named) - len(rows)
    if missing:
        console.print(
            f"{missing} student{'s' if missing != 1 else ''} on the roster handed nothing in",
            markup=False,
            highlight=False,
        )
    if unknown:
        listed = ", ".join(for_terminal(n) for n in unknown)
        console.print(f"not on the roster (no id): {listed}", markup=False, highlight=False)
    return sorted(named, key=lambda g: (g.name.casefold(), g.name))


def _gradebook(
    grades: list[StudentGrade], plan: ScorePlan, book: GradebookSettings, *, rostered: bool
) -> bytes:
    """gradebook.csv: with a roster, the roster's students alone (an id the LMS does not
    know stops Moodle's import); without one, each folder's name as the id (what an LMS
    export names the folders by)."""
    from harness.grading.gradebook import gradebook_csv

    return gradebook_csv(
        [(g.student_id if rostered else g.name, g.full_name or g.name, g.points) for g in grades],
        column=book.column,
        max_score=plan.max_score,
        id_header=book.ids,
    )


def _write_gradescope(
    students: list[Student],
    grades: list[StudentGrade],
    plan: ScorePlan,
    out: Path,
    *,
    enabled: bool,
) -> None:
    """One Gradescope results.json per graded student, in their own folder."""
    if not enabled:
        return
    from harness.atomic_write import write_atomically
    from harness.grading.gradescope import gradescope_results

    for student, grade in zip(students, grades, strict=True):
        data = gradescope_results(
            plan,
            grade.verdicts,
            grade.ticks,
            grade.failures,
            notes=grade.notes,
            execution_time=grade.run_s,
        )
        path = out / "students" / student.slug / "gradescope" / "results.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomically(path, json.dumps(data, indent=2).encode())
