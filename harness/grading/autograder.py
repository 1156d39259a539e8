"""One submission, graded as Gradescope's run_autograder grades it (examples/gradescope/).

Two steps, each a command the script calls, so that whatever fails, the
student still gets a results.json saying why:

``python -m harness.grading.autograder prepare SUBMISSION WORK [--grading FILE]``
    finds what the submission holds, by `grade`'s rules (a colcon workspace, a
    package or one node script; a lone archive is unpacked first, lone
    wrapper folders are looked through), builds a workspace or package with
    colcon into WORK (bounded, the log in WORK/build.log), and prints the
    `fossbot-hil run` options that start its node, one per line. When there
    is nothing to run it prints why, for the student, and exits 1.
``python -m harness.grading.autograder not-graded --reason TEXT --out FILE [--grading FILE]``
    writes a results.json in which every scenario of the grading file earns
    0 points, the reason in its output.

Student code is only read here (colcon's setup.py runs, as in `grade`); the
reasons printed are for students: no path of the grader's machine.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from harness.errors import ConfigError, one_line
from harness.grading import LAB_EXECUTABLE, LAB_PACKAGE
from harness.grading.student_text import for_students
from harness.run_request.table import option

if TYPE_CHECKING:
    from harness.grading.scoring import ScorePlan

__all__ = ["main", "node_options", "not_graded"]

BUILD_TIMEOUT_S = 300.0
EXIT_NOT_GRADED = 1


class NotGraded(Exception):
    """Why a submission cannot be run, in words for its student."""


def _visible(folder: Path) -> list[Path]:
    from harness.grading.discover import passed_over

    try:
        return sorted(p for p in folder.iterdir() if not passed_over(p.name))
    except OSError as err:
        raise NotGraded(f"the submission cannot be read: {err.strerror or err}") from None


def hand_in(submission: Path, work: Path) -> Path:
    """The folder that holds the hand-in: a lone archive unpacked into WORK/unpacked, lone
    wrapper folders looked through (never into src/)."""
    from harness.grading.archives import Refused, unpack
    from harness.grading.discover import is_archive

    if not submission.is_dir():
        raise NotGraded("nothing was handed in")
    folder = submission
    entries = _visible(folder)
    if len(entries) == 1 and entries[0].is_file() and is_archive(entries[0]):
        try:
            unpack(entries[0], work / "unpacked")
        except Refused as err:
            raise NotGraded(f"{entries[0].name}: {err}") from None
        folder = work / "unpacked"
        entries = _visible(folder)
    while len(entries) == 1 and entries[0].is_dir() and not entries[0].is_symlink():
        if entries[0].name == "src":
            break
        folder = entries[0]
        entries = _visible(folder)
    return folder


def node_options(
    submission: Path,
    work: Path,
    *,
    package: str = LAB_PACKAGE,
    executable: str = LAB_EXECUTABLE,
    build_timeout: float = BUILD_TIMEOUT_S,
) -> list[str]:
    """The `fossbot-hil run` options that start the submission's node (built into `work`);
    NotGraded says why there is none."""
    from harness.grading.build import build_student
    from harness.grading.discover import student_in

    work.mkdir(parents=True, exist_ok=True)
    student = student_in(hand_in(submission, work), "submission")
    if student.kind == "script" and student.script is not None:
        command = f"{shlex.quote(sys.executable)} {shlex.quote(str(student.script.resolve()))}"
        return [option("node").cli, command]
    if student.kind in ("package", "workspace"):
        built = build_student(
            student,
            work / "colcon",
            package=package,
            executable=executable,
            log=work / "build.log",
            timeout=build_timeout,
        )
        if not built.ok:
            raise NotGraded(f"did not build: {built.error}")
        given = {"workspace": str(built.workspace), "package": package, "executable": executable}
        return [arg for key, value in given.items() for arg in (option(key).cli, value)]
    raise NotGraded(student.problem or "no node found")


def _plan(grading: str | None) -> ScorePlan:
    """The grading file's plan (a scenario file that cannot be read is named by its file);
    without one, every shipped scenario weighs 1."""
    from harness.grading.scoring import ScenarioScore, ScorePlan
    from harness.scenario.files import resolve_scenario, shipped_scenarios

    if not grading:
        return ScorePlan.equal([s.name for s in shipped_scenarios()])
    from harness.grading.grading_file import load_grading_file

    loaded = load_grading_file(grading)
    entries = []
    for p in loaded.planned:
        try:
            name = resolve_scenario(p.scenario).name
        except ConfigError:
            name = Path(p.scenario).stem
        entries.append(ScenarioScore(name, p.weight, p.hidden, p.show_failure, p.label or ""))
    return ScorePlan(tuple(entries), points=loaded.points, partial_credit=loaded.partial_credit)


def not_graded(reason: str, out: Path, grading: str | None = None) -> Path:
    """Write results.json for a submission that could not be run: 0 points, `reason`."""
    from harness.atomic_write import write_atomically
    from harness.grading.gradescope import not_graded_results

    data = not_graded_results(_plan(grading), reason)
    text = json.dumps(data, indent=2, ensure_ascii=False) + "\n"
    return write_atomically(out, text.encode("utf-8"))


def _grading_node(grading: str | None) -> tuple[str, str]:
    """The package and executable the grading file names (default: the lab's)."""
    if not grading:
        return LAB_PACKAGE, LAB_EXECUTABLE
    from harness.grading.grading_file import load_grading_file

    loaded = load_grading_file(grading)
    return loaded.package or LAB_PACKAGE, loaded.executable or LAB_EXECUTABLE


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m harness.grading.autograder")
    steps = parser.add_subparsers(dest="step", required=True)
    prepare = steps.add_parser("prepare", help="find and build the submission's node")
    prepare.add_argument("submission", type=Path)
    prepare.add_argument("work", type=Path)
    prepare.add_argument("--grading", help="the grading file (its package and executable)")
    prepare.add_argument("--build-timeout", type=float, default=BUILD_TIMEOUT_S)
    failed = steps.add_parser("not-graded", help="write results.json: 0 points, and why")
    failed.add_argument("--reason", required=True)
    failed.add_argument("--out", type=Path, required=True)
    failed.add_argument("--grading", help="the grading file (its scenarios and weights)")
    args = parser.parse_args(argv)
    try:
        if args.step == "not-graded":
            not_graded(args.reason, args.out, args.grading)
            return 0
        package, executable = _grading_node(args.grading)
        options = node_options(
            args.submission,
            args.work,
            package=package,
            executable=executable,
            build_timeout=args.build_timeout,
        )
    except NotGraded as err:
        print(for_students(str(err)).replace("\n", " "))
        return EXIT_NOT_GRADED
    except ConfigError as err:  # the grader's setup, not the student's hand-in
        print(f"fossbot-hil: error: {one_line(err, 1000)}", file=sys.stderr)
        print(f"the autograder failed (tell your instructor): {for_students(one_line(err))}")
        return EXIT_NOT_GRADED
    print("\n".join(options))
    return 0


if __name__ == "__main__":
    sys.exit(main())
