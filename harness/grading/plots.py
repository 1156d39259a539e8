"""A class's report plots, drawn by the grader's workers beside their next student's run.

A student's judging process (in its sandbox) leaves each scenario's plot as
its data (``harness.report.plot.series_data``, JSON) in the grader's own
folder for that student, and its report names the PNG as usual. The worker
that graded the student then draws the PNGs into the student's report in a
process of its own while its next student runs: matplotlib is imported
once a worker instead of once a student, and the drawing runs beside the
next run instead of before it. It runs at the worker's priority: at a nice
value of 10 it starved whenever the machine had other work (its plots then
waited for the class's end, 20 s after the last student on a machine at load
11). ``grade_class`` waits (bounded) for every worker's plots before it
returns, so the reports are whole when ``grade`` ends. The data is read as
JSON only and the PNG's name is checked: nothing a judging process writes can
make the grader run code or write outside the student's report.
"""

from __future__ import annotations

import json
import queue
import re
import subprocess
import sys
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from harness.atomic_write import write_atomically

if TYPE_CHECKING:
    from harness.judge.records import RunResult
    from harness.report.outputs import PromisedArtifactWriter

__all__ = ["PLOT_WAIT_S", "PlotRequests", "Plotter", "draw_requested", "plots_drawn", "plotter"]

REQUEST_SUFFIX = ".plot.json"
DONE = b"done\n"
# For a worker's plots once its last student is graded: a student's seven plots take
# about 0.5 CPU-s, and a worker may have several students' left on a loaded machine.
PLOT_WAIT_S = 120.0
_PNG_NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]*\.png")


@dataclass(frozen=True)
class PlotRequests:
    """The judging process's side: the report's plot writer leaves each plot's data in
    `folder` (the grader's folder for this student) instead of drawing it."""

    folder: Path

    def writer(self) -> PromisedArtifactWriter:
        from harness.report.outputs import PromisedArtifactWriter

        return PromisedArtifactWriter("plot", ".png", self.leave)

    def leave(self, final: Path, result: RunResult) -> Path:
        from harness.report.plot import plot_series, series_data

        data = {"png": final.name, "series": series_data(plot_series(result))}
        self.folder.mkdir(parents=True, exist_ok=True)
        write_atomically(self.folder / f"{final.stem}{REQUEST_SUFFIX}", json.dumps(data).encode())
        return final


def draw_requested(requests: Path, scenarios: Path) -> list[str]:
    """Draw every plot left in `requests` into `scenarios` (the student's report folder);
    what could not be drawn, a line each."""
    from harness.report.plot import render_plot, series_from_data

    if scenarios.is_symlink() or not scenarios.is_dir():
        return [f"{scenarios}: not the report's folder"]
    problems: list[str] = []
    for path in sorted(requests.glob(f"*{REQUEST_SUFFIX}")):
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            name = str(data["png"])
            if not _PNG_NAME.fullmatch(name):
                raise ValueError(f"not a plot's file name: {name!r}")
            write_atomically(scenarios / name, render_plot(series_from_data(data["series"])))
        except Exception as err:  # noqa: BLE001 - one plot lost, never the worker's thread
            problems.append(f"{path.name}: {type(err).__name__}: {err}")
    return problems


def _draw_logged(requests: Path, scenarios: Path, log: Path) -> None:
    """`draw_requested`, its problems written to `log`; never raises."""
    try:
        problems = draw_requested(requests, scenarios)
        if problems:
            write_atomically(log, ("\n".join(problems) + "\n").encode())
    except Exception:  # noqa: BLE001, S110 - the log's folder went away: nothing to tell
        pass


Job = tuple[Path, Path, Path]  # the plots' data, the report's scenarios folder, the log


class Plotter:
    """Draws students' plots in a process of its own (started when first needed,
    matplotlib imported there once), fed a student at a time by a thread of ours: the
    drawing never holds the worker's GIL. A student's plots are drawn by that thread
    itself if the process is lost."""

    def __init__(self) -> None:
        self._jobs: queue.SimpleQueue[Job] = queue.SimpleQueue()
        self._pending = 0
        self._changed = threading.Condition()
        self._thread: threading.Thread | None = None
        self._child: subprocess.Popen[bytes] | None = None

    @property
    def child_pid(self) -> int | None:
        """The plotting process's pid, once started."""
        return None if self._child is None else self._child.pid

    def submit(self, requests: Path, scenarios: Path, log: Path) -> None:
        """Draw the plots left in `requests` into `scenarios` soon; problems go to `log`."""
        with self._changed:
            self._pending += 1
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(
                    target=self._feed, name="fossbot-hil-plots", daemon=True
                )
                self._thread.start()
        self._jobs.put((requests, scenarios, log))

    def _feed(self) -> None:
        while True:
            job = self._jobs.get()
            try:
                if not self._in_child(job):
                    _draw_logged(*job)
            finally:
                self._done()

    def _in_child(self, job: Job) -> bool:
        """Have the plotting process draw `job` (started if need be); False if it could not."""
        try:
            child = self._child
            if child is None or child.poll() is not None:
                child = self._child = subprocess.Popen(
                    [sys.executable, "-m", "harness.grading.plots"],
                    stdin=subprocess.PIPE,
                    stdout=subprocess.PIPE,
                    stderr=subprocess.DEVNULL,
                )
            assert child.stdin is not None and child.stdout is not None
            request = dict(zip(("requests", "scenarios", "log"), map(str, job), strict=True))
            child.stdin.write(json.dumps(request).encode() + b"\n")
            child.stdin.flush()
            return child.stdout.readline() == DONE  # b"": it died; drawn here instead
        except OSError:
            self._child = None
            return False

    def _done(self) -> None:
        with self._changed:
            self._pending -= 1
            self._changed.notify_all()

    def wait_drawn(self, timeout: float) -> bool:
        """Wait up to `timeout` s for every plot given so far; True if all are drawn.
        (Not drawn here: this process has no matplotlib imported, the plotting one has.)"""
        with self._changed:
            return self._changed.wait_for(lambda: self._pending == 0, timeout)


_PLOTTER = Plotter()


def plotter() -> Plotter:
    """This process's plotter (a Dask worker's: the students it graded)."""
    return _PLOTTER


async def plots_drawn(timeout: float = PLOT_WAIT_S) -> bool:
    """For ``client.run`` on every worker: its plots drawn (bounded), without blocking
    the worker's event loop while it waits."""
    import asyncio

    return await asyncio.get_running_loop().run_in_executor(None, _PLOTTER.wait_drawn, timeout)


def main() -> int:
    """The plotting process: a JSON job a line on stdin, ``done`` a line on stdout once
    drawn; it ends with its stdin (the worker that started it is gone)."""
    for line in sys.stdin.buffer:
        try:
            job = json.loads(line)
            _draw_logged(Path(job["requests"]), Path(job["scenarios"]), Path(job["log"]))
        except (ValueError, KeyError, TypeError):
            pass
        sys.stdout.buffer.write(DONE)
        sys.stdout.buffer.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
