"""The node under test as a separate process: start, watch, stop, reap.

The node is started the way a user would start it (``command``: a shell
command, a colcon workspace's package/executable, or the bundled reference
node), with ``--ros-args`` appended. It runs under a
small reaper process (``reaper.py``, a child subreaper) in its own
session, so stopping it also stops everything it started, even processes
that left its process group or session, and so does the harness dying. Its
stdout and stderr are read as they come and only their tails kept, so a
chatty node never blocks on a full pipe and a flooding one fills nothing.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import re
import select
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from harness.errors import ConfigError
from harness.nodes.command import NodeCommand
from harness.nodes.forkserver import ForkedSupervisor, ForkServer
from harness.nodes.forkserver import shared as shared_fork_server
from harness.nodes.python_script import SERVER_MODULE as SCRIPT_SERVER_MODULE
from harness.nodes.python_script import ScriptCommand, plan_start, script_command
from harness.nodes.sandbox_prefix import node_sandbox_prefix, parent_for

REAPER = Path(__file__).with_name("reaper.py")
INT_GRACE_S = 2.0  # a ROS 2 node stops on SIGINT well within this
TERM_GRACE_S = 1.0  # then SIGTERM; then SIGKILL
START_WAIT_S = 10.0  # for the reaper (a Python start-up) to report the node started
# The reaper's own bounds (reaper.py: graces, SIGKILL wait, leftovers), plus slack.
STOP_WAIT_S = INT_GRACE_S + TERM_GRACE_S + 5.0 + 0.5 + 5.0 + 2.0
POLL_S = 0.05
TAIL_BYTES = 16384
FORK_SERVER_SETTING = "FOSSBOT_HIL_FORK_SERVER"
LAST_WORDS_S = 0.5  # after the node exited: for its output's readers to reach end of file
LINE_CHARS = 300  # a longer line in a tail is cut (a flood may have no newlines)
_FINISHED = "(finished on its own: a node must keep running until it is stopped)"


def fork_server_enabled() -> bool:
    """Start Python nodes by fork from a warm process? Not when
    ``FOSSBOT_HIL_FORK_SERVER=0``. Any thread may (a Dask worker runs its tasks in
    a thread of its own): the server is started from a thread that lasts
    (``forkserver.shared``)."""
    return os.environ.get(FORK_SERVER_SETTING, "1") != "0"


def _fork_server_of(command: NodeCommand) -> str | None:
    """The module of the fork server that may start `command` (None: none may)."""
    if not fork_server_enabled():
        return None
    if command.module is not None:
        return command.module
    found = script_command(command.argv, {**os.environ, **command.env})
    return SCRIPT_SERVER_MODULE if isinstance(found, ScriptCommand) else None


def prepare_start(command: NodeCommand) -> None:
    """Start what starting `command` will use (its fork server), so it is ready sooner."""
    module = _fork_server_of(command)
    if module is not None:
        shared_fork_server(module)


def start_would_wait(command: NodeCommand) -> bool:
    """Would starting `command` now wait for its fork server's imports? (Then the
    caller can do its own work first.)"""
    module = _fork_server_of(command)
    return module is not None and shared_fork_server(module).still_importing()


_LIVE: set[NodeProcess] = set()


def _stop_all_at_exit() -> None:
    for process in list(_LIVE):
        process.stop()


atexit.register(_stop_all_at_exit)


class OutputTail:
    """The last bytes of a node's stdout or stderr, read by a thread as they come.

    The pipe is always drained, so a chatty (or flooding) node never blocks
    on it, and only the tail is kept, so neither memory nor disk grows with
    what it writes.
    """

    def __init__(self, fd: int, name: str, keep: int = TAIL_BYTES) -> None:
        self.total = 0  # bytes written, all told
        self._keep = keep
        self._buffer = bytearray()
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._pump, args=(fd,), name=name, daemon=True)
        self._thread.start()

    def _pump(self, fd: int) -> None:
        try:
            while chunk := os.read(fd, 1 << 16):
                with self._lock:
                    self.total += len(chunk)
                    self._buffer += chunk
                    if len(self._buffer) > 2 * self._keep:
                        del self._buffer[: -self._keep]
        except OSError:
            pass
        finally:
            os.close(fd)

    def text(self) -> str:
        with self._lock:
            return bytes(self._buffer[-self._keep :]).decode("utf-8", "replace")

    def last_lines(self, lines: int = 15) -> str:
        """The last lines written (very long lines cut)."""
        kept = self.text().rstrip().splitlines()[-lines:]
        return "\n".join(
            line if len(line) <= LINE_CHARS else f"{line[:LINE_CHARS]}... ({len(line)} characters)"
            for line in kept
        )

    def join(self, timeout: float) -> None:
        """Wait (bounded) for end of file: every process holding the pipe has exited."""
        self._thread.join(timeout)


_FRAME = re.compile(r'^\s*File "(?P<file>[^"]+)", line (?P<line>\d+), in (?P<func>.+)$')
_CARETS = re.compile(r"^\s*[\^~]+\s*$")


def last_error(stderr: str) -> str:
    """What a crashed node's stderr says went wrong, in one line.

    A Python traceback gives its exception line and where it was raised
    (``ValueError: min() arg is an empty sequence (node.py line 85, in
    on_scan: best = min(valid))``); other output gives its last three lines
    joined with " | ". Empty when nothing was written.
    """
    lines = [line.rstrip() for line in stderr.splitlines() if line.strip()]
    frames = [i for i, line in enumerate(lines) if _FRAME.match(line)]
    if frames:
        at = frames[-1]
        after = [line for line in lines[at + 1 :] if not _CARETS.match(line)]
        code = after[0].strip() if after and after[0].startswith(" ") else ""
        error = next((line for line in after if not line.startswith(" ")), "")
        if error:
            frame = _FRAME.match(lines[at])
            assert frame is not None
            where = f"{Path(frame['file']).name} line {frame['line']}, in {frame['func']}"
            return f"{error} ({where}{': ' + code if code else ''})"
    return " | ".join(lines[-3:])


def signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def how_it_ended(code: int) -> str:
    """An exit code in words: 'exited with code 1', or 'was killed by SIGKILL' (negative)."""
    return f"was killed by {signal_name(-code)}" if code < 0 else f"exited with code {code}"


class NodeProcess:
    """One running node under test, started under reaper.py (see there)."""

    def __init__(
        self, command: NodeCommand, args: list[str], env: dict[str, str], *, held: int | None = None
    ) -> None:
        """`held`: a descriptor the node's supervisor holds open until the node and all
        it started are gone (the run's domain lock: a node that outlives its harness,
        killed, keeps its domain from the next run until it is stopped)."""
        self.command = command
        self._held = held
        self.argv = [*command.argv, *args]
        self.env = {**os.environ, **command.env, **env, "PYTHONUNBUFFERED": "1"}
        self._popen: subprocess.Popen[bytes] | ForkedSupervisor | None = None  # the reaper
        self._status_fd: int | None = None
        self._partial = b""
        self._outputs: dict[str, OutputTail] = {}
        self.node_pid: int | None = None
        self.start_error: str | None = None
        self._code: int | None = None
        self.stopped_by: str | None = None  # "exited", "SIGINT", "SIGTERM" or "SIGKILL"
        self.stop_seconds = 0.0
        self.leftovers: list[str] = []  # "PID (name)" of processes killed after the node
        self.stop_problem: str | None = None
        self._done = False  # the reaper finished its stop (its last event)
        self._stop_requested = False
        self.started_at = 0.0  # monotonic: when `start` set it on its way
        self._start_pending = False  # started without waiting: `await_started` waits
        self._last_words_read = False  # `_last_words` has waited for the output's end
        self.how = "started as a command"  # how `start` started it, for the user

    def start(self, *, wait: bool = True) -> None:
        """Start the node under the reaper; wait (bounded) until it runs or cannot.

        With `wait` false, return once it is on its way: `await_started` waits (a
        link started ahead does not hold the run up while the node forks).
        """
        status_r, status_w = os.pipe()
        out_r, out_w = os.pipe()
        err_r, err_w = os.pipe()
        sandbox = node_sandbox_prefix()  # grading: the node's nested sandbox
        reaper = [sys.executable, "-I", "-S", str(REAPER)]  # it needs the standard library only
        graces = [f"{INT_GRACE_S:g}", f"{TERM_GRACE_S:g}"]
        argv = [*sandbox, *reaper, str(status_w), parent_for(sandbox), *graces, "--", *self.argv]
        held = [] if self._held is None else [self._held]
        try:
            self._popen = self._forked([status_w, out_w, err_w, *held]) or subprocess.Popen(
                argv,
                stdin=subprocess.DEVNULL,
                stdout=out_w,
                stderr=err_w,
                env=self.env,
                start_new_session=True,  # a Ctrl-C on the terminal is the harness's to handle
                pass_fds=(status_w, *held),
            )
        except OSError as error:
            for fd in (status_r, out_r, err_r):
                os.close(fd)
            raise ConfigError(f"cannot start {self.command.description}: {error}") from None
        finally:
            for fd in (status_w, out_w, err_w):
                os.close(fd)
        os.set_blocking(status_r, False)
        self._status_fd = status_r
        pipes = {"stdout": out_r, "stderr": err_r}
        self._outputs = {name: OutputTail(fd, f"node-{name}") for name, fd in pipes.items()}
        _LIVE.add(self)
        self.started_at = time.monotonic()
        self._start_pending = True
        if wait:
            self.await_started()

    def await_started(self) -> None:
        """Wait (bounded) until the reaper says the node runs; ConfigError if it cannot.

        What the reaper reported already is read first, and the bound
        (START_WAIT_S) counts from this call, not from `start`: a link started
        ahead may be awaited long after its node came up (a suite of a slow
        node), and that is no failure to start.
        """
        if self.node_pid is not None or not self._start_pending:
            return
        self._read_events()
        deadline = time.monotonic() + START_WAIT_S
        while self.node_pid is None and self.start_error is None and self._status_fd is not None:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            self._read_events(min(POLL_S, left))
        self._start_pending = False
        if self.node_pid is None:
            self.returncode()  # the reaper's last words, if it has exited
            why = self.start_error or self._no_start_report()
            self.stop()
            raise ConfigError(f"cannot start {self.command.description}: {why}")

    def _no_start_report(self) -> str:
        """Why the node is not known to run, though nothing said it failed: in the node's
        own words where it wrote any."""
        said = (self.tail("stderr", 3) or self.tail("stdout", 3)).replace("\n", " | ")
        words = f"; it wrote: {said}" if said else "; it wrote nothing"
        if self._status_fd is None:
            return f"its supervisor ({REAPER.name}) exited before the node ran{words}"
        return (
            f"the node was not running {START_WAIT_S:g} s after the harness began waiting for "
            f"it (its supervisor, {REAPER.name}, reported nothing: a machine too busy to start "
            f"a process?){words}"
        )

    def _forked(self, fds: list[int]) -> ForkedSupervisor | None:
        """The node started by a fork server (a module of this interpreter, or a Python
        script that may be served: ``python_script``), or None; `how` says which."""
        graces = (INT_GRACE_S, TERM_GRACE_S)
        if not fork_server_enabled():
            self.how = f"started as a command ({FORK_SERVER_SETTING}=0)"
            return None
        module = self.command.module
        if module is not None:
            server = shared_fork_server(module)
            argv = self.argv[len(self.command.argv) :]
            started = server.start(argv, self.env, graces, fds)
            self.how = "started by fork from a warm Python" if started else self._fallback(server)
            return started
        server = shared_fork_server(SCRIPT_SERVER_MODULE)
        if not server.ready():
            self.how = self._fallback(server)
            return None
        facts = {"version": server.version, "modules": server.modules, "server_env": server.env}
        plan = plan_start(self.argv, self.env, **facts)
        self.how = plan.how
        if plan.script is None:
            return None
        argv = list(plan.args)
        started = server.start(
            argv, self.env, graces, fds, script=plan.script, sys_path=list(plan.sys_path)
        )
        if started is None:
            self.how = self._fallback(server)
        return started

    @staticmethod
    def _fallback(server: ForkServer) -> str:
        return f"started as a command: the fork server is not usable ({server.problem})"

    # -- what the reaper reports --------------------------------------------
    def _read_events(self, timeout: float = 0.0) -> None:
        """Take the reaper's event lines, waiting at most `timeout` for the first."""
        fd = self._status_fd
        if fd is None:
            return
        if timeout > 0:
            select.select([fd], [], [], timeout)
        while True:
            try:
                chunk = os.read(fd, 4096)
            except BlockingIOError:
                return
            if not chunk:  # the reaper has exited
                self._status_fd = None  # first: a Ctrl-C landing after the close leaves no
                os.close(fd)  # stale number, which another pipe may take (EBADF, or worse)
                return
            *lines, self._partial = (self._partial + chunk).split(b"\n")
            for line in lines:
                self._event(line.decode("utf-8", "replace"))

    def _event(self, line: str) -> None:
        kind, _, rest = line.partition(" ")
        if kind == "started":
            self.node_pid = int(rest)
        elif kind == "error":
            self.start_error = rest
        elif kind == "exited":
            self._code = int(rest)
        elif kind == "stopped":
            how, _, seconds = rest.partition(" ")
            self.stopped_by, self.stop_seconds = how, float(seconds or 0)
        elif kind == "leftover":
            pid, _, name = rest.partition(" ")
            self.leftovers.append(name if pid == "0" else f"{pid} ({name})")
        elif kind == "done":
            self._done = True

    @property
    def pid(self) -> int | None:
        """The node's own process id (not its reaper's)."""
        return self.node_pid

    def returncode(self) -> int | None:
        """None while running; the exit code (negative: killed by that signal) after."""
        if self._popen is None:
            return None
        self._read_events()
        if self._code is None and self._popen.poll() is not None:
            self._read_events(POLL_S)  # the reaper's last words
            if self._code is None:  # the reaper was killed (not by us): so was its node
                self._code = self._popen.returncode or -signal.SIGKILL
        return self._code

    def output_bytes(self, which: str = "stderr") -> int:
        """How much the node wrote on stdout or stderr, all told."""
        output = self._outputs.get(which)
        return output.total if output else 0

    def tail(self, which: str = "stderr", lines: int = 15) -> str:
        """The last lines the node wrote on stdout or stderr (very long lines cut)."""
        output = self._outputs.get(which)
        return output.last_lines(lines) if output is not None else ""

    def _last_words(self) -> None:
        """Once the node has exited: let its output's readers take what is still in the
        pipes (bounded: a process it left behind may hold them open), so its last stderr
        lines are in the tail before a crash is explained. A loaded machine may not have
        run the reader thread yet when the exit is seen. Once, within one bound."""
        if self._last_words_read:
            return
        self._last_words_read = True
        end = time.monotonic() + LAST_WORDS_S
        for output in self._outputs.values():
            output.join(max(0.0, end - time.monotonic()))

    def exit_summary(self, when: str = "") -> str:
        """`exited with code 1 <when>; last stderr: ...` for failure explanations."""
        code = self.returncode()
        if code is None:
            return "still running"
        self._last_words()
        words = [how_it_ended(code), when, _FINISHED if code == 0 else ""]
        last = self.tail("stderr", 3).replace("\n", " | ")
        return " ".join(w for w in words if w) + (f"; last stderr: {last}" if last else "")

    def crash_summary(self, when: str = "") -> str:
        """How the node ended and why, for the tick it died on: "crashed <when>: it exited
        with code 1; last stderr: ValueError: ... (node.py line 85, in on_scan: ...)"."""
        code = self.returncode()
        if code is None:
            return "is still running"
        self._last_words()
        at = f" {when}" if when else ""
        if code:
            how = f"crashed{at}: it {how_it_ended(code)}"
        else:
            how = f"exited with code 0 {_FINISHED}"
        last = last_error(self.tail("stderr"))
        return how + (f"; last stderr: {last}" if last else "")

    def stop_note(self) -> str:
        """What stopping took beyond a plain SIGINT: signals ignored, processes left behind."""
        notes = []
        if self.stopped_by == "SIGTERM":
            notes.append(f"did not stop on SIGINT within {INT_GRACE_S:g} s; SIGTERM stopped it")
        elif self.stopped_by == "SIGKILL":
            notes.append(
                f"ignored SIGINT ({INT_GRACE_S:g} s) and SIGTERM ({TERM_GRACE_S:g} s): "
                f"killed with SIGKILL, {self.stop_seconds:.1f} s after the stop began"
            )
        if self.leftovers:
            count = len(self.leftovers)
            notes.append(
                f"left {count} process{'es' if count > 1 else ''} running after it stopped "
                f"(killed): {', '.join(self.leftovers)}"
            )
        if self.stop_problem:
            notes.append(self.stop_problem)
        return "; ".join(notes)

    def request_stop(self) -> None:
        """Ask the reaper to stop the node and everything it started; do not wait (see stop)."""
        if self._popen is not None and not self._stop_requested and self._popen.poll() is None:
            self._popen.send_signal(signal.SIGTERM)  # the reaper's cue to stop its node
            self._stop_requested = True

    def stop(self) -> int | None:
        """Stop the node and everything it started (SIGINT, SIGTERM, SIGKILL; bounded); reap all."""
        if self._popen is None:
            return None
        if self._popen.poll() is None:
            self.request_stop()
            try:
                self._popen.wait(timeout=STOP_WAIT_S)
            except subprocess.TimeoutExpired:
                self._popen.kill()
                with contextlib.suppress(subprocess.TimeoutExpired):
                    self._popen.wait(timeout=STOP_WAIT_S)
                self.stop_problem = f"its reaper did not finish within {STOP_WAIT_S:g} s"
        end = time.monotonic() + 1.0
        while self._status_fd is not None and time.monotonic() < end:
            self._read_events(POLL_S)
        if not self._done and self.node_pid is not None:  # the reaper died (or hung) early
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self.node_pid, signal.SIGKILL)
            self.stop_problem = self.stop_problem or "its reaper died before it stopped the node"
            self.stop_problem += ": killed the node's process group"
        for output in self._outputs.values():
            output.join(1.0)
        _LIVE.discard(self)
        return self.returncode()
