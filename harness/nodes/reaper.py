"""Run one command so that nothing it starts outlives it: a child subreaper.

``process`` starts every node through this program (by path, stdlib only, never
imported). As a child subreaper (``PR_SET_CHILD_SUBREAPER``) it keeps every process
the node starts as a descendant, even after a double fork and ``setsid``. Asked to
stop (SIGTERM, SIGINT, SIGHUP; Linux sends one if the harness dies) it stops the node
(SIGINT, SIGTERM, SIGKILL, each after a bounded wait), kills and reaps every
descendant left, and exits. The fork server runs the same ``supervise`` in a forked child.

Usage: ``python3 reaper.py STATUS_FD PARENT_PID INT_GRACE TERM_GRACE -- ARGV...``;
STATUS_FD gets one event a line: ``started PID``, ``error MESSAGE``, ``exited CODE``
(negative: that signal), ``stopped HOW SECONDS`` (``exited``, or the signal that ended
it), ``leftover PID NAME`` for each process killed after the node, ``done``."""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import sys
import time
from collections.abc import Callable

PR_SET_PDEATHSIG = 1
PR_SET_CHILD_SUBREAPER = 36
KILL_WAIT_S = 5.0  # after SIGKILL: only a process stuck in the kernel takes this long
LEFTOVER_GRACE_S = 0.5  # the node's own group got the signal too: let it finish exiting
REPORTED = 20  # leftover processes named, at most
WATCHED = {signal.SIGCHLD, signal.SIGTERM, signal.SIGINT, signal.SIGHUP}
# The node starts with these at their defaults, whatever the harness inherited
# (Python ignores SIGPIPE; a background job may ignore SIGINT): exec keeps SIG_IGN.
DEFAULT_SIGNALS = tuple(
    getattr(signal, f"SIG{n}") for n in ("INT", "TERM", "HUP", "QUIT", "PIPE", "XFSZ")
)


class Reaper:
    """The node's parent: relays its exit, stops it and its descendants on request."""

    def __init__(self, status_fd: int, int_grace: float, term_grace: float) -> None:
        self.status_fd = status_fd
        self.graces = ((signal.SIGINT, int_grace), (signal.SIGTERM, term_grace))
        self.node = 0
        self.code: int | None = None

    def emit(self, line: str) -> None:
        with contextlib.suppress(OSError):  # the harness is gone: carry on stopping everything
            os.write(self.status_fd, f"{line}\n".encode(errors="replace"))

    def reap(self) -> None:
        """Collect every child that has exited; note the node's exit code."""
        while True:
            try:
                pid, status = os.waitpid(-1, os.WNOHANG)
            except ChildProcessError:
                return
            if pid == 0:
                return
            if pid == self.node:
                self.code = os.waitstatus_to_exitcode(status)
                self.emit(f"exited {self.code}")

    def wait(self, seconds: float, done) -> bool:
        """Reap children until `done()` or `seconds` pass; True if done."""
        end = time.monotonic() + seconds
        while not done():
            left = end - time.monotonic()
            if left <= 0:
                return False
            if signal.sigtimedwait([signal.SIGCHLD], left) is not None:
                self.reap()
        return True

    def start(self, launch: Callable[[], int]) -> bool:
        """Start the node with `launch` (which returns its pid); report how that went."""
        try:
            self.node = launch()
        except OSError as err:
            self.emit(f"error {err}")
            return False
        self.emit(f"started {self.node}")
        return True

    def serve(self) -> None:
        """Relay exits until a stop is asked for."""
        while signal.sigwaitinfo(WATCHED).si_signo == signal.SIGCHLD:
            self.reap()

    def stop(self) -> None:
        """The node: SIGINT, SIGTERM, SIGKILL to its group; then every descendant left."""
        started = time.monotonic()
        how = "exited"
        self.reap()
        for sig, grace in self.graces:
            if self.code is not None:
                break
            how = sig.name
            _signal_group(self.node, sig)
            self.wait(grace, lambda: self.code is not None)
        if self.code is None:
            how = "SIGKILL"
            _signal_group(self.node, signal.SIGKILL)
            self.wait(KILL_WAIT_S, lambda: self.code is not None)
        self.emit(f"stopped {how} {time.monotonic() - started:.2f}")
        self.wait(LEFTOVER_GRACE_S, lambda: not _descendants(os.getpid()))
        self.kill_leftovers()
        self.emit("done")

    def kill_leftovers(self) -> None:
        """SIGKILL every live descendant, round after round, until none is left (bounded)."""
        named: dict[int, str] = {}
        end = time.monotonic() + KILL_WAIT_S
        while time.monotonic() < end:
            self.reap()
            alive = _descendants(os.getpid())
            if not alive:
                break
            for pid, name in alive.items():
                named.setdefault(pid, name)
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)
            self.wait(0.05, lambda: False)
        self.reap()  # the last ones killed: no zombie is left to init
        for pid, name in list(named.items())[:REPORTED]:
            self.emit(f"leftover {pid} {name}")
        if len(named) > REPORTED:
            self.emit(f"leftover 0 ...and {len(named) - REPORTED} more")


def _signal_group(pid: int, sig: int) -> None:
    """Signal the node's process group (it leads its own session), and the node too only if
    it left that group. Never twice to the node: a Python node's second SIGINT, once its
    teardown began, kills it (exit -2, a clean stop judged a crash), as a stop preempted
    between two sends on a loaded machine was seen to."""
    try:
        in_group = os.getpgid(pid) == pid
    except (ProcessLookupError, PermissionError):
        in_group = False
    for send in (os.killpg,) if in_group else (os.killpg, os.kill):
        with contextlib.suppress(ProcessLookupError, PermissionError):
            send(pid, sig)


def _descendants(root: int) -> dict[int, str]:
    """Live (not zombie) descendants of `root` and their names, from /proc."""
    children: dict[int, list[int]] = {}
    name: dict[int, str] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as handle:
                stat = handle.read().decode(errors="replace")
        except OSError:
            continue  # exited meanwhile
        head, _, tail = stat.rpartition(")")
        fields = tail.split()
        if len(fields) < 2 or fields[0] == "Z":
            continue
        children.setdefault(int(fields[1]), []).append(int(entry))
        name[int(entry)] = head.partition("(")[2].replace(" ", "_") or "?"
    found: dict[int, str] = {}
    frontier = [root]
    while frontier:
        for pid in children.get(frontier.pop(), []):
            if pid not in found:
                found[pid] = name[pid]
                frontier.append(pid)
    return found


def spawn(argv: list[str]) -> int:
    """Start `argv` in its own session with default signal handling; its pid."""
    return os.posix_spawnp(
        argv[0], argv, os.environ, setsid=True, setsigmask=(), setsigdef=DEFAULT_SIGNALS
    )


def _keep_descriptors_from_the_node(status_fd: int) -> None:
    """Close-on-exec for every descriptor above stderr: the node started by `spawn`
    gets none of them (this process keeps them open)."""
    try:
        open_fds = [int(name) for name in os.listdir("/proc/self/fd")]
    except OSError:  # no /proc (a sandbox without one): the harness's pipe at least
        open_fds = [status_fd]
    for fd in open_fds:
        if fd > 2:
            with contextlib.suppress(OSError):  # the listing's own descriptor, gone
                os.set_inheritable(fd, False)


def supervise(reaper: Reaper, parent: int, launch: Callable[[], int]) -> int:
    """Become the node's subreaper, start it, relay its exit until asked to stop; stop it.
    `parent`'s death stops everything (PDEATHSIG); returns this process's exit code."""
    _keep_descriptors_from_the_node(reaper.status_fd)  # the harness's pipe, the domain lock
    signal.pthread_sigmask(signal.SIG_BLOCK, WATCHED)  # taken by sigwaitinfo, never async
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
    if os.getppid() != parent:  # the parent died before PDEATHSIG was set
        return 1
    if not reaper.start(launch):
        return 127
    reaper.serve()
    reaper.stop()
    return 0


def main(argv: list[str]) -> int:
    try:
        status_fd, parent, int_grace, term_grace = argv[:4]
        separator = argv.index("--", 4)
        command = argv[separator + 1 :]
        reaper = Reaper(int(status_fd), float(int_grace), float(term_grace))
        parent_pid = int(parent) or os.getppid()  # 0: a sandbox's launcher started us
    except ValueError:
        print(__doc__, file=sys.stderr)
        return 2
    if not command:
        return 127
    return supervise(reaper, parent_pid, lambda: spawn(command))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
