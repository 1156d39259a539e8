"""One judging process a grading worker keeps across its script students, in its sandbox.

A fresh judging process costs each student about a second of CPU before their first
scan (Python, the runner, the ROS 2 link, the MCAP writer) and its fork server's
imports after that. So a worker keeps one (``python -m harness.grading.warm_judge``),
started in a sandbox that shows, besides the system and the scenarios, only the
worker's *slot*: ``slot/node`` (the current student's files, read-only; the node's
nested sandbox shows that alone) and ``slot/out`` (the current student's outputs).
The worker copies a student's files into the slot, hands the judge a job, and moves
the outputs to the student's folders afterwards.

Between students the judge ends every process left in its PID namespace but its own
(a node's daemon included: nested namespaces are seen from here), empties its
/dev/shm (shared with the nodes for DDS) and only then starts the next student's
fork server, in a fresh nested sandbox (fresh /tmp and home); the worker then
replaces the slot's files. A student's code never sees another's files or what the
previous one left. A student who overruns, floods the log or is cancelled takes the
judge down (stopped as a fresh one is); the next student gets a new judge.
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Slot", "WarmJudge", "close_judges", "drop_judge", "end_strays", "warm_judge"]

STRAY_WAIT_S = 5.0  # for what a student left running to be gone once killed
START_WAIT_S = 30.0  # for a started judge to take its first job (it reads stdin at once)
DONE = "done"


# -- in the sandbox -----------------------------------------------------------


def _pids() -> list[int]:
    return [int(p) for p in os.listdir("/proc") if p.isdigit()]


def _alive(pid: int) -> bool:
    """Running or stopped, not a zombie (a zombie holds nothing and is reaped by its
    parent, or by the sandbox's init once orphaned)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as stat:
            state = stat.read().rsplit(b")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in (b"Z", b"X")


def _reap_children() -> None:
    with contextlib.suppress(ChildProcessError):
        while os.waitpid(-1, os.WNOHANG)[0]:
            pass


def end_strays(wait_s: float = STRAY_WAIT_S) -> bool:
    """SIGKILL every live process of this PID namespace but its init (1) and us, until
    none is left; False if some still live after `wait_s` (the judge then exits), or if
    this is not a sandbox's PID namespace (its init is not bwrap): nothing is killed."""
    try:
        with open("/proc/1/comm", encoding="utf-8") as comm:
            if comm.read().strip() != "bwrap":
                return False
    except OSError:
        return False
    ends = time.monotonic() + wait_s
    while True:
        _reap_children()
        others = [pid for pid in _pids() if pid not in (1, os.getpid()) and _alive(pid)]
        if not others:
            return True
        if time.monotonic() > ends:
            return False
        fds = []
        for pid in others:
            with contextlib.suppress(OSError):
                fds.append(os.pidfd_open(pid))
                os.kill(pid, signal.SIGKILL)
        try:  # bounded: the kills take effect, or the loop looks again
            select.select(fds, [], [], max(0.0, min(0.2, ends - time.monotonic())))
        finally:
            for fd in fds:
                os.close(fd)


def _empty(folder: str) -> None:
    for name in os.listdir(folder):
        path = os.path.join(folder, name)
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                os.unlink(path)


def _to(fd: int) -> None:
    """This process's stdout and stderr (and its children's) to `fd`."""
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(fd, 1)
    os.dup2(fd, 2)


def serve(sandboxed: bool) -> int:
    """Judge a job a line on stdin (``{"job", "log", "plot_cache"}``), its account in `log`; ``done
    CODE`` a line on the original stdout once judged and, sandboxed, once nothing of the
    student is left. Ends with stdin, or when a student's processes cannot be ended."""
    from harness.grading.worker import interrupt_on_sigterm, not_dumpable, run_job, warm_node_server
    from harness.option_names import speak
    from harness.run_request.table import names
    from harness.runner.frame_memo import remember_frames

    speak(names("grading"))  # a student's problems name the options as the grading file does
    remember_frames()  # the class's scenarios are simulated once, for the first student

    # The jobs and answers on fds of their own (not inherited): what the judge starts
    # (a node's reaper) gets /dev/null as its stdin and the job's log as its output.
    jobs = os.fdopen(os.dup(0), "r")
    answers = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
    quiet = os.open(os.devnull, os.O_WRONLY)
    _to(quiet)
    interrupt_on_sigterm()
    if sandboxed:
        not_dumpable()
    warmed = False
    for line in jobs:
        request = json.loads(line)
        if request.get("plot_cache") and "MPLCONFIGDIR" not in os.environ:  # before matplotlib
            os.environ["MPLCONFIGDIR"] = request["plot_cache"]
        job = json.loads(Path(request["job"]).read_text(encoding="utf-8"))
        log = os.open(request["log"], os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
        _to(log)
        try:
            if not warmed:
                warm_node_server(job)
                _import_beside()
            code = run_job(job)  # closes the fork server at its end
        except KeyboardInterrupt:
            return 1
        finally:
            _to(quiet)
            os.close(log)
        if sandboxed:
            if not end_strays():
                return 1
            _empty("/dev/shm")
        warmed = warm_node_server(job)  # the next student's: a fresh nested sandbox
        answers.write(f"{DONE} {code}\n")
    return 0


def _import_beside() -> None:
    """The first job's imports: the runner's here (the run needs them first), the plots'
    and recordings' in a thread, while the run waits for its first node to start (the
    first plot's matplotlib import was a second on the first student's way)."""
    import harness.links.ros2  # noqa: F401 - what run_job imports first, before the thread
    import harness.runner.suite  # noqa: F401

    def report_parts() -> None:
        import harness.record  # noqa: F401
        from harness.report.plot import prepare_canvas

        prepare_canvas()

    threading.Thread(target=report_parts, name="fossbot-hil-report-imports", daemon=True).start()


# -- in the grading worker ------------------------------------------------------


@dataclass(frozen=True)
class Slot:
    """A worker's folders for the student its judge is on: `node` (their files, read-only
    in the sandbox), `student` and `grader` (their outputs, moved out once judged)."""

    root: Path

    @property
    def node(self) -> Path:
        return self.root / "node"

    @property
    def student(self) -> Path:
        return self.root / "out" / "student"

    @property
    def grader(self) -> Path:
        return self.root / "out" / "grader"

    @property
    def plot_cache(self) -> Path:
        """matplotlib's cache for the judge (its home is an empty tmpfs), kept while the slot
        lasts: the font list, which matplotlib builds in a quarter second of CPU otherwise."""
        return self.root / "out" / ".matplotlib"

    def fill(self, files: Path | None, leave_out: Path) -> Path:
        """The slot emptied, then `files` (a student's folder, without `leave_out`, the
        grader's own folder should it be inside) in it: where they now are. Hard links
        where the file system allows (the sandbox shows them read-only). Without
        `files`: where a build goes (``node/colcon``)."""
        self.empty()
        for folder in (self.node, self.student, self.grader):
            folder.mkdir(parents=True, exist_ok=True)
        _seed_plot_cache(self.plot_cache)
        if files is None:
            return self.node / "colcon"
        copy = self.node / files.name
        skipped = str(leave_out.resolve())

        def ignored(folder: str, names: list[str]) -> list[str]:
            return [n for n in names if os.path.join(os.path.realpath(folder), n) == skipped]

        shutil.copytree(files, copy, symlinks=True, ignore=ignored, copy_function=_link_or_copy)
        return copy

    def move_out(self, student: Path, grader: Path, build: Path | None = None) -> None:
        """The outputs into the student's and the grader's folders, and the build (the
        slot's ``node/colcon``) to `build`; the slot emptied."""
        for source, target in ((self.student, student), (self.grader, grader)):
            for entry in sorted(source.iterdir()) if source.is_dir() else ():
                shutil.move(str(entry), str(target / entry.name))
        if build is not None and (self.node / "colcon").is_dir():
            shutil.move(str(self.node / "colcon"), str(build))
        self.empty()

    def empty(self) -> None:
        """What the slot holds removed; its folders stay (the judge's sandbox binds them:
        a folder made anew would not be the one it sees)."""
        for folder in (self.node, self.student, self.grader):
            if folder.is_dir():
                _empty(str(folder))

    def moved(self, copy: Path, files: Path, student: Path, grader: Path) -> Callable[[str], str]:
        """What turns a text's paths in the slot into the ones outside it."""
        pairs = ((copy, files), (self.student, student), (self.grader, grader))

        def moved(text: str) -> str:
            for inside, outside in pairs:
                text = text.replace(str(inside), str(outside))
            return text

        return moved


def _seed_plot_cache(cache: Path) -> None:
    """The worker's own matplotlib font list (if it has one) in the judge's cache, once."""
    if cache.is_dir():
        return
    cache.mkdir(parents=True)
    home = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    mine = Path(os.environ.get("MPLCONFIGDIR") or os.path.join(home, "matplotlib"))
    for fonts in sorted(mine.glob("fontlist-*.json")) if mine.is_dir() else ():
        with contextlib.suppress(OSError):
            shutil.copy2(fonts, cache / fonts.name)


def _link_or_copy(source: str, target: str) -> None:
    try:
        os.link(source, target, follow_symlinks=False)
    except OSError:
        shutil.copy2(source, target)


class WarmJudge:
    """The worker's end of a judge: `argv` started (from a thread that lasts, so its
    PDEATHSIG fires only with the worker) in the slot, fed one job at a time."""

    def __init__(self, argv: list[str], slot: Path) -> None:
        from harness.nodes.forkserver import from_a_lasting_thread

        self.argv = argv
        self.slot = slot
        self.popen: subprocess.Popen[str] = from_a_lasting_thread(
            lambda: subprocess.Popen(
                argv,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                cwd=slot,
                env={**os.environ, "PYTHONUNBUFFERED": "1"},
                start_new_session=True,
                text=True,
            )
        )

    def judge(
        self, job: Path, log: Path, *, timeout: float, max_log_bytes: int, cancel: object
    ) -> tuple[object, bool]:
        """Judge `job` (its account in `log`): (Finished, whether this judge can take the
        next student). Stopped on timeout, flood or `cancel` as a fresh judge is."""
        from harness.grading.process import POLL_S, Finished, stop_child

        started = time.monotonic()
        deadline = started + timeout
        popen = self.popen
        assert popen.stdin is not None and popen.stdout is not None
        log.touch()
        try:
            cache = str(Slot(self.slot).plot_cache)
            popen.stdin.write(json.dumps({"job": str(job), "log": str(log), "plot_cache": cache}))
            popen.stdin.write("\n")
            popen.stdin.flush()
        except OSError:
            return Finished(popen.poll(), 0.0, start_error="the judging process had ended"), False
        why = ""
        while not why:
            left = deadline - time.monotonic()
            readable, _, _ = select.select([popen.stdout], [], [], max(0.0, min(POLL_S, left)))
            if readable:
                answer = popen.stdout.readline().split()
                if len(answer) == 2 and answer[0] == DONE:
                    return Finished(int(answer[1]), time.monotonic() - started), True
                stop_child(popen)  # it said something else, or ended: not reused
                return Finished(popen.returncode, time.monotonic() - started), False
            if time.monotonic() >= deadline:
                why = "timed_out"
            elif log.stat().st_size > max_log_bytes:
                why = "flooded"
            elif cancel is not None and cancel.is_set():  # type: ignore[attr-defined]
                why = "cancelled"
        stop_child(popen)
        return Finished(popen.returncode, time.monotonic() - started, **{why: True}), False

    def close(self) -> None:
        from harness.grading.process import stop_child

        with contextlib.suppress(OSError):
            if self.popen.stdin is not None:
                self.popen.stdin.close()  # it ends with its stdin
        stop_child(self.popen)
        shutil.rmtree(self.slot, ignore_errors=True)


# This process's judges, one a worker (a worker's slot): the embedded cluster's workers
# are threads of one process, an external cluster's are processes of their own.
_JUDGES: dict[Path, WarmJudge] = {}
_JUDGES_TURN = threading.Lock()


def warm_judge(argv: list[str], slot: Path) -> WarmJudge:
    """The judge of the worker whose slot is `slot`, for `argv` (the same sandbox view),
    started if need be; one of another view, or one that ended, is closed first."""
    with _JUDGES_TURN:
        judge = _JUDGES.get(slot)
        if judge is not None and (judge.argv != argv or judge.popen.poll() is not None):
            del _JUDGES[slot]
            judge.close()
        if slot not in _JUDGES:
            _JUDGES[slot] = WarmJudge(argv, slot)
        return _JUDGES[slot]


def drop_judge(judge: WarmJudge) -> None:
    """`judge` is not to be used again (stopped already)."""
    with _JUDGES_TURN:
        if _JUDGES.get(judge.slot) is judge:
            del _JUDGES[judge.slot]
    judge.close()


def close_judges(under: str) -> None:
    """Close the judges whose slots are `under` (a class's grader folder): ``client.run``
    at a class's end, since an external cluster's workers outlive the grading (and may
    serve another grading meanwhile)."""
    with _JUDGES_TURN:
        judges = [j for j in _JUDGES.values() if j.slot.is_relative_to(under)]
    for judge in judges:
        drop_judge(judge)


if __name__ == "__main__":
    sys.exit(serve("--sandboxed" in sys.argv[1:]))
