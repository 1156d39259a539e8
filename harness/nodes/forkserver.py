"""Start Python nodes by fork from a process that has imported what they import.

A node's interpreter start and imports (rclpy, the message packages, numpy)
cost about 0.3-0.5 s of CPU, paid again for every scenario. The fork server
pays it once: it imports a module (nothing more: no rclpy context, no DDS
participant, no thread of its own), then forks per request. Each fork is a
fresh process that has never run a node; it supervises the node exactly as
``reaper.py`` does (``supervise``: subreaper, own session, the same stop and
the same events), and the node itself is a second fork, with the request's
environment, arguments and working folder, that runs either

- the server's module as ``python -m MODULE ARGS`` would (the bundled
  nodes: their server imports them), or
- a script, as ``python SCRIPT ARGS`` would, with the module search path a
  fresh interpreter would have (students' nodes: their server imports
  ``warm_python``, never the student's code, so the script and what it
  imports are read afresh by every node).

Which commands may be served so is the harness's to decide
(``python_script``); anything else is started by ``reaper.py`` as before.

The harness side (`ForkServer`) starts the server lazily, once per process,
and falls back to the plain start if the server cannot come up. The server
exits when the harness closes its socket or dies (PDEATHSIG). PDEATHSIG
follows the thread that started it, so a server wanted from any thread but
the main one (a Dask worker's task) is started from one lasting thread of
this module's, and requests from several threads take turns.

Protocol, over a SOCK_SEQPACKET socket pair: the server sends ``ready JSON``
(its Python version and where each module it imported came from) or
``error MESSAGE`` once; each request is JSON (argv, env, graces, cwd, and
for a script its path and sys.path) with three descriptors (the status
pipe, stdout, stderr) and optionally a fourth that the supervisor holds
open until it ends (the run's domain lock); the answer is JSON (the
supervisor's pid, or an error) with a pidfd of the supervisor.
"""

from __future__ import annotations

import atexit
import contextlib
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from harness.nodes.quick_exit import exit_now, finish_interpreter
from harness.nodes.sandbox_prefix import node_sandbox_prefix, parent_for

READY_WAIT_S = 10.0  # for the server's imports (a cold disk cache is slow)
ANSWER_WAIT_S = 5.0  # for a fork
MESSAGE_BYTES = 1 << 20  # a request carries the environment
REAP_EVERY_S = 0.5  # the server collects its exited children this often
STARTER_WAIT_S = 30.0  # for the lasting thread to start a server (a Popen)
T = TypeVar("T")


class ForkedSupervisor:
    """The subset of ``subprocess.Popen`` NodeProcess uses, for a supervisor that is
    not the harness's child: watched and signalled through its pidfd.

    Its exit status belongs to the fork server (its parent), so `returncode`
    is 0 once it has gone; the supervisor's own events say how the node ended.
    """

    def __init__(self, pid: int, pidfd: int) -> None:
        self.pid = pid
        self._pidfd: int | None = pidfd
        self.returncode: int | None = None

    def poll(self) -> int | None:
        return self.wait(0.0, raise_timeout=False)

    def wait(self, timeout: float | None = None, *, raise_timeout: bool = True) -> int | None:
        if self.returncode is None and self._pidfd is not None:
            readable, _, _ = select.select([self._pidfd], [], [], timeout)
            if readable:
                self.returncode = 0
                os.close(self._pidfd)
                self._pidfd = None
            elif raise_timeout:
                raise subprocess.TimeoutExpired(f"supervisor {self.pid}", timeout or 0.0)
        return self.returncode

    def send_signal(self, sig: int) -> None:
        if self._pidfd is not None:
            with contextlib.suppress(ProcessLookupError):
                signal.pidfd_send_signal(self._pidfd, sig)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)

    def __del__(self) -> None:
        if self._pidfd is not None:
            with contextlib.suppress(OSError):
                os.close(self._pidfd)


class ForkServer:
    """The harness's end: one server per harness process and module, started on first
    use (``shared``); any thread may use it, one request at a time."""

    def __init__(self, module: str) -> None:
        self.module = module
        self._turn = threading.RLock()  # one request (and its answer) at a time
        self.problem: str | None = None  # why the server is not used, once known
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self._socket: socket.socket | None = ours
        # What the server's interpreter started with: what a node started anew gets.
        self.env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        try:
            sandbox = node_sandbox_prefix()  # grading: the nodes' nested sandbox
            argv = [*sandbox, sys.executable, "-m", __name__, str(theirs.fileno())]
            self._process: subprocess.Popen[bytes] | None = subprocess.Popen(
                [*argv, parent_for(sandbox), module],
                pass_fds=(theirs.fileno(),),
                env=self.env,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,  # a Ctrl-C on the terminal is the harness's to handle
            )
        except OSError as err:
            self._process = None
            self._fail(f"cannot start the fork server: {err}")
        finally:
            theirs.close()
        self._ready = False
        self.version = ""  # the server's sys.version, once it is ready
        # Where each module the server imported came from (top-level names): a
        # script is served only where its own imports would find the same.
        self.modules: dict[str, str] = {}

    def _fail(self, problem: str) -> None:
        self.problem = self.problem or problem
        if self._socket is not None:
            self._socket.close()
            self._socket = None

    def _receive(self, timeout: float) -> tuple[bytes, list[int]]:
        assert self._socket is not None
        readable, _, _ = select.select([self._socket], [], [], timeout)
        if not readable:
            raise TimeoutError(f"no answer within {timeout:g} s")
        message, fds, _, _ = socket.recv_fds(self._socket, MESSAGE_BYTES, 1)
        if not message:
            raise ConnectionError("the fork server exited")
        return message, fds

    def ready(self) -> bool:
        """Wait (bounded) until the server has imported its module; False if it cannot."""
        with self._turn:
            if not self._ready and self._socket is not None:
                try:
                    message, _ = self._receive(READY_WAIT_S)
                except (OSError, TimeoutError) as err:
                    self._fail(f"the fork server did not come up: {err}")
                    return False
                kind, _, detail = message.partition(b" ")
                if kind != b"ready":
                    self._fail(message.decode(errors="replace"))
                    return False
                facts = json.loads(detail or b"{}")
                self.version = str(facts.get("version", ""))
                self.modules = dict(facts.get("modules", {}))
                self._ready = True
            return self._ready

    def still_importing(self) -> bool:
        """Would a start wait for the server's imports now? (It has not said ready.)"""
        if not self._turn.acquire(blocking=False):
            return not self._ready  # another thread is waiting for it or using it
        try:
            if self._ready or self._socket is None:
                return False
            readable, _, _ = select.select([self._socket], [], [], 0)
            return not readable
        finally:
            self._turn.release()

    def start(
        self,
        argv: list[str],
        env: dict[str, str],
        graces: tuple[float, float],
        fds: list[int],
        *,
        script: str | None = None,
        sys_path: list[str] | None = None,
    ) -> ForkedSupervisor | None:
        """Fork a supervisor running `self.module` (or `script`, with `sys_path` as its
        module search path) with `argv`, in this process's working folder; None when
        the server is not usable (then `problem` says why, and the caller starts the
        node itself)."""
        request: dict[str, object] = {"argv": argv, "env": env, "graces": graces}
        request["cwd"] = os.getcwd()
        if script is not None:
            request.update(script=script, sys_path=sys_path or [])
        with self._turn:  # reentrant: the wait for ready takes its turn too
            if not self.ready():
                return None
            assert self._socket is not None
            try:
                socket.send_fds(self._socket, [json.dumps(request).encode()], fds)
                message, pidfds = self._receive(ANSWER_WAIT_S)
            except (OSError, TimeoutError) as err:
                self._fail(f"the fork server stopped answering: {err}")
                return None
        answer = json.loads(message)
        if "error" in answer or len(pidfds) != 1:
            for fd in pidfds:
                os.close(fd)
            self._fail(f"the fork server could not fork: {answer.get('error', '?')}")
            return None
        return ForkedSupervisor(int(answer["pid"]), pidfds[0])

    def close(self) -> None:
        """Stop the server (its children, supervisors still stopping, carry on alone)."""
        with self._turn:
            self._fail("closed")
        if self._process is not None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                self._process.wait(timeout=2.0)
            if self._process.poll() is None:
                self._process.kill()
                self._process.wait()
            self._process = None


_SERVERS: dict[str, ForkServer] = {}
_SCOPES = [0]  # open `scope()`s


@contextlib.contextmanager
def scope() -> Iterator[None]:
    """Fork servers started within it stop when the outermost scope ends.

    A command or a suite opens one, so nothing it started outlives it; a
    server started outside any scope (a test session's runs one by one)
    lives until the process exits.
    """
    _SCOPES[0] += 1
    try:
        yield
    finally:
        _SCOPES[0] -= 1
        if not _SCOPES[0]:
            close_all()


_SHARED = threading.Lock()
_starter: ThreadPoolExecutor | None = None  # the lasting thread that starts servers


def shared(module: str) -> ForkServer:
    """This process's fork server for `module`, started on first use (closed at exit)."""
    with _SHARED:
        server = _SERVERS.get(module)
        if server is None:
            if not _SERVERS:
                atexit.register(close_all)
            server = _SERVERS[module] = from_a_lasting_thread(lambda: ForkServer(module))
    return server


def from_a_lasting_thread(make: Callable[[], T]) -> T:
    """`make()` in the main thread, or in a thread that lasts as long as the process: a
    child's PDEATHSIG fires when the thread that started it ends, and a worker's task
    thread may end before the process does."""
    global _starter
    if threading.current_thread() is threading.main_thread():
        return make()
    if _starter is None:
        _starter = ThreadPoolExecutor(max_workers=1, thread_name_prefix="fossbot-hil-fork-servers")
    return _starter.submit(make).result(timeout=STARTER_WAIT_S)


def close_all() -> None:
    for server in _SERVERS.values():
        server.close()
    _SERVERS.clear()


# -- the server -------------------------------------------------------------


def _serve(sock: socket.socket, module: str) -> int:
    """Answer fork requests until the harness closes its end."""
    while True:
        readable, _, _ = select.select([sock], [], [], REAP_EVERY_S)
        _reap_children()
        if not readable:
            continue
        try:
            message, fds, _, _ = socket.recv_fds(sock, MESSAGE_BYTES, 4)
        except OSError:
            return 0
        if not message:
            return 0
        try:
            request = json.loads(message)
            if len(fds) not in (3, 4):
                raise ValueError(f"expected 3 or 4 descriptors, got {len(fds)}")
            pid = os.fork()
        except (OSError, ValueError) as err:
            for fd in fds:
                os.close(fd)
            socket.send_fds(sock, [json.dumps({"error": str(err)}).encode()], [])
            continue
        if pid == 0:
            _supervisor(sock, module, request, fds)  # never returns
        for fd in fds:
            os.close(fd)
        pidfd = os.pidfd_open(pid)
        socket.send_fds(sock, [json.dumps({"pid": pid}).encode()], [pidfd])
        os.close(pidfd)


def _reap_children() -> None:
    with contextlib.suppress(ChildProcessError):
        while os.waitpid(-1, os.WNOHANG)[0]:
            pass


def _supervisor(sock: socket.socket, module: str, request: dict, fds: list[int]) -> None:
    """The forked child: supervise a node that is a fork of this one."""
    code = 1
    try:
        from harness.nodes.reaper import Reaper, supervise

        sock.close()
        status_fd, out_fd, err_fd, *kept = fds  # kept: held open until the supervisor ends
        os.setsid()
        null = os.open(os.devnull, os.O_RDONLY)
        for fd, target in ((null, 0), (out_fd, 1), (err_fd, 2)):
            os.dup2(fd, target)
            os.close(fd)
        int_grace, term_grace = request["graces"]
        reaper = Reaper(status_fd, float(int_grace), float(term_grace))
        parent = os.getppid()
        code = supervise(reaper, parent, lambda: _fork_node(module, request, [status_fd, *kept]))
    finally:
        os._exit(code)


def _fork_node(module: str, request: dict, supervisors: list[int]) -> int:
    """Fork the node: in the child, become what ``python -m MODULE ARGV`` (or
    ``python SCRIPT ARGV``) would be, without the supervisor's descriptors."""
    pid = os.fork()
    if pid:
        return pid
    code = 1
    try:
        for fd in supervisors:
            os.close(fd)
        os.setsid()
        signal.pthread_sigmask(signal.SIG_SETMASK, [])  # the supervisor blocks its signals
        os.environ.clear()
        os.environ.update(request["env"])
        code = _run(module, request)
    finally:
        exit_now(code)


def _run(module: str, request: dict) -> int:
    """Run the request's script (or `module`) as __main__; the exit code the
    interpreter would give."""
    import importlib
    import runpy

    script = request.get("script")
    try:
        os.chdir(request.get("cwd") or ".")
        if script is not None:
            sys.path[:] = request["sys_path"]
            importlib.invalidate_caches()  # files may have changed since the server looked
            sys.argv = [script, *request["argv"]]
            if not os.path.isfile(script):  # as the interpreter says it
                print(f"{sys.executable}: can't open file {script!r}", file=sys.stderr)
                return 2
            runpy.run_path(script, run_name="__main__")
        else:
            sys.argv = [module, *request["argv"]]
            runpy.run_module(module, run_name="__main__", alter_sys=True)
        code = 0
    except SystemExit as stop:
        code = _exit_code(stop.code)
    except KeyboardInterrupt:
        finish_interpreter()
        signal.signal(signal.SIGINT, signal.SIG_DFL)  # as Python does: die by the signal
        os.kill(os.getpid(), signal.SIGINT)
        code = 128 + signal.SIGINT  # not reached
    except BaseException as error:  # as the interpreter does with any uncaught error
        _print_uncaught(error)
        code = 1
    return code


def _print_uncaught(error: BaseException) -> None:
    """The traceback a fresh interpreter would print: from the node's own code on,
    without this server's and runpy's frames."""
    import runpy
    import traceback

    ours = {__file__, runpy.__file__, "<frozen runpy>"}
    tb = error.__traceback__
    while tb is not None and tb.tb_frame.f_code.co_filename in ours:
        tb = tb.tb_next
    traceback.print_exception(type(error), error, tb)


def _exit_code(value: object) -> int:
    """What ``sys.exit(value)`` makes the interpreter's exit code."""
    if value is None:
        return 0
    if isinstance(value, int):
        return value & 0xFF
    print(value, file=sys.stderr)
    return 1


# What every rclpy node uses besides its own topics' types: parameter
# services and events, /rosout, /clock (use_sim_time), type descriptions.
NODE_INTERFACES = (
    "rcl_interfaces.msg",
    "rcl_interfaces.srv",
    "rosgraph_msgs.msg",
    "type_description_interfaces.srv",
)


def _load_type_support() -> None:
    """Load the C type support of every ROS interface imported so far (and of those
    every node uses): each node would otherwise load the same libraries again,
    at its first publisher, subscription or service."""
    import importlib

    for name in NODE_INTERFACES:
        with contextlib.suppress(ImportError):
            importlib.import_module(name)
    for loaded in list(sys.modules.values()):
        for value in list(getattr(loaded, "__dict__", {}).values()):
            load = getattr(type(value), "__import_type_support__", None)
            if isinstance(value, type) and load is not None:
                with contextlib.suppress(Exception):  # a node that needs it will say why
                    load()


def imported_modules() -> dict[str, str]:
    """Where each top-level module imported so far came from (its file, 'built-in',
    'frozen', or its folders for a namespace package); the harness's own left out."""
    found = {}
    for name, module in list(sys.modules.items()):
        spec = getattr(module, "__spec__", None)
        if "." in name or name in ("__main__", "harness") or spec is None:
            continue
        locations = spec.submodule_search_locations
        found[name] = spec.origin or os.pathsep.join(locations or ())
    return found


def main(argv: list[str]) -> int:
    """``python -m harness.nodes.forkserver SOCKET_FD PARENT_PID MODULE``."""
    import ctypes
    import importlib

    fd, parent, module = argv
    sock = socket.socket(fileno=int(fd))
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG: go when the harness goes
    if os.getppid() != (int(parent) or os.getppid()):  # 0: a sandbox's launcher started us
        return 1
    try:
        importlib.import_module(module)
        # Keep what it imported, not the module itself: each node runs it
        # afresh as __main__ (runpy warns about a module already imported).
        del sys.modules[module]
        _load_type_support()
    except BaseException as err:  # reported to the harness, which then starts nodes itself
        socket.send_fds(sock, [f"error cannot import {module}: {err!r}".encode()], [])
        return 1
    facts = {"version": sys.version, "modules": imported_modules()}
    socket.send_fds(sock, [b"ready " + json.dumps(facts).encode()], [])
    code = _serve(sock, module)
    os._exit(code)  # nothing to clean up: the harness waits for this exit, so make it quick


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
