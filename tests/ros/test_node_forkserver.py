"""The bundled node started by fork from a warm process: the same node, the same hygiene."""

from __future__ import annotations

import contextlib
import os
import select
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from child_process import alive

from harness.errors import ConfigError
from harness.links.base import LinkOptions
from harness.nodes.command import NodeCommand, reference_node, ros_arguments
from harness.nodes.forkserver import ForkedSupervisor, ForkServer, _exit_code
from harness.nodes.process import FORK_SERVER_SETTING, NodeProcess
from harness.nodes.reaper import _signal_group
from harness.ros.domain import discovery_environment, reserve_domain
from harness.runner.suite import run_suite
from harness.scenario.files import resolve_scenario

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]


def wait_until(condition, seconds: float) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


@contextlib.contextmanager
def started_node(*, wait: bool = True) -> Iterator[NodeProcess]:
    """The reference node, started in a domain of its own; stopped and released after."""
    domain = reserve_domain(None)
    environment = {"ROS_DOMAIN_ID": str(domain.domain_id), **discovery_environment(network=False)}
    process = NodeProcess(reference_node(), ros_arguments(("threshold:=0.4",)), environment)
    try:
        process.start(wait=wait)
        yield process
    finally:
        process.stop()
        domain.release()


def test_the_reference_node_is_forked_and_stops_cleanly() -> None:
    with started_node() as process:
        assert isinstance(process._popen, ForkedSupervisor)  # started by the fork server
        assert process.node_pid is not None and alive(process.node_pid)
        # A real node: it logs its topics and the threshold it was given.
        assert wait_until(lambda: "threshold 0.4 m" in process.tail("stderr"), 10), process.tail()
        node = process.node_pid
        assert process.stop() == 0
        assert process.stopped_by == "SIGINT" and not process.leftovers and not process.stop_note()
        assert not alive(node)


def test_turned_off_the_node_starts_as_a_command(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(FORK_SERVER_SETTING, "0")
    with started_node() as process:
        assert isinstance(process._popen, subprocess.Popen)
        assert wait_until(lambda: "threshold 0.4 m" in process.tail("stderr"), 15), process.tail()
        assert process.stop() == 0


# Counts the SIGINTs it gets, one line each, and stops 0.3 s after the first: a second
# SIGINT sent in that time is counted (a real node's would come during its teardown,
# when the default action is back, and kill it: exit -2).
COUNTING_NODE = """
import signal, sys, time
stop = 0.0
def on_sigint(signum, frame):
    global stop
    with open(sys.argv[1], "a") as handle:
        handle.write("SIGINT\\n")
    stop = stop or time.monotonic() + 0.3
signal.signal(signal.SIGINT, on_sigint)
print("up", flush=True)
end = time.monotonic() + 30
while time.monotonic() < end and not (stop and time.monotonic() >= stop):
    time.sleep(0.01)
"""


@pytest.mark.parametrize("fork_server", ["1", "0"])
def test_a_node_is_sent_sigint_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fork_server: str
) -> None:
    """The stop signals the node's process group, which the node leads: not the node too.
    Twice, a stop preempted between the sends (a loaded machine) killed a node that was
    stopping cleanly (the reference node exited -2, not 0)."""
    monkeypatch.setenv(FORK_SERVER_SETTING, fork_server)
    script, count = tmp_path / "counting_node.py", tmp_path / "sigints"
    script.write_text(COUNTING_NODE)
    process = NodeProcess(NodeCommand((sys.executable, str(script), str(count))), [], {})
    process.start()
    assert wait_until(lambda: "up" in process.tail("stdout"), 15), process.tail()
    assert process.stop() == 0
    assert process.stopped_by == "SIGINT"
    assert count.read_text().splitlines() == ["SIGINT"]


# A group leader that counts the SIGRTMINs it gets: real-time signals queue, so two sent
# are two taken, however close together (two SIGINTs may merge into one).
QUEUED_COUNTER = """
import os, signal, sys
signal.pthread_sigmask(signal.SIG_BLOCK, [signal.SIGRTMIN])
print("up", flush=True)
count = 0
while signal.sigtimedwait([signal.SIGRTMIN], 10 if count == 0 else 0.5) is not None:
    count += 1
print(count, flush=True)
"""


def test_the_stop_signals_a_node_leading_its_group_once() -> None:
    """A signal of the stop reaches the node once: its group's, not its group's and its own."""
    child = subprocess.Popen(
        [sys.executable, "-c", QUEUED_COUNTER],
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        assert child.stdout is not None and child.stdout.readline() == "up\n"
        _signal_group(child.pid, signal.SIGRTMIN)
        assert child.communicate(timeout=20)[0] == "1\n"
    finally:
        child.kill()
        child.wait(timeout=10)


def test_a_server_that_cannot_import_its_module_is_not_used() -> None:
    server = ForkServer("harness.no_such_module")
    try:
        read, write = os.pipe()
        try:
            assert server.start(["x"], dict(os.environ), (1.0, 1.0), [write, write, write]) is None
        finally:
            os.close(read)
            os.close(write)
        assert "cannot import harness.no_such_module" in (server.problem or "")
    finally:
        server.close()


@pytest.mark.parametrize(
    ("body", "code", "stderr"),
    [
        ("import sys\nsys.exit(3)", 3, ""),
        ("raise SystemExit('bad parameter')", 1, "bad parameter"),
        ("raise RuntimeError('boom')", 1, "RuntimeError: boom"),
        ("import signal, os\nos.kill(os.getpid(), signal.SIGTERM)", -signal.SIGTERM, ""),
        ("raise KeyboardInterrupt", -signal.SIGINT, ""),
    ],
)
def test_a_forked_module_exits_as_its_interpreter_would(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, body: str, code: int, stderr: str
) -> None:
    """Exit codes and uncaught errors look as they would from ``python -m MODULE``."""
    main = textwrap.indent(body, "    ")
    (tmp_path / "ending_node.py").write_text(
        f"def main():\n{main}\n\n\nif __name__ == '__main__':\n    main()\n"
    )
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    server = ForkServer("ending_node")
    try:
        monkeypatch.setattr("harness.nodes.process.shared_fork_server", lambda module: server)
        command = NodeCommand((sys.executable, "-m", "ending_node"), module="ending_node")
        process = NodeProcess(command, [], {})
        process.start()
        assert isinstance(process._popen, ForkedSupervisor), server.problem
        assert wait_until(lambda: process.returncode() is not None, 10)
        assert process.returncode() == code
        process.stop()
        assert stderr in process.tail("stderr")
    finally:
        server.close()


def test_exit_code_of_sys_exit_values() -> None:
    assert _exit_code(None) == 0
    assert _exit_code(2) == 2
    assert _exit_code(256 + 4) == 4


def test_a_killed_harness_takes_its_forked_nodes_along(tmp_path: Path) -> None:
    """SIGKILL the harness: the fork server, each supervisor and each node go too."""
    script = tmp_path / "harness_that_dies.py"
    script.write_text(
        textwrap.dedent(
            """
            import os, sys, time
            from harness.nodes.command import reference_node, ros_arguments
            from harness.nodes.process import NodeProcess
            env = {"ROS_DOMAIN_ID": sys.argv[1], "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
            process = NodeProcess(reference_node(), ros_arguments(()), env)
            process.start()
            print(process.node_pid, flush=True)
            time.sleep(60)
            """
        )
    )
    domain = reserve_domain(None)
    try:
        harness = subprocess.Popen(
            [sys.executable, str(script), str(domain.domain_id)], stdout=subprocess.PIPE, text=True
        )
        assert harness.stdout is not None
        node = int(harness.stdout.readline())
        assert alive(node)
        harness.kill()
        harness.wait()
        assert wait_until(lambda: not alive(node), 10), f"node {node} outlived its harness"
    finally:
        domain.release()


def test_overlapping_scenarios_get_fresh_nodes_in_their_own_domains() -> None:
    """Started ahead and stopped behind, every scenario still has a node of its own."""
    names = ["approach_wall", "obstacle_at_side", "out_of_range", "reverse_to_wall"]
    scenarios = [resolve_scenario(n) for n in names]
    seen: list[tuple[float, int | None, int | None]] = []  # (opened at, node pid, domain)
    starts: list[float] = []  # when each node was started
    from harness.links.ros2 import Ros2Link

    opened = Ros2Link.open

    def recording_open(link: Ros2Link) -> None:
        opened(link)
        assert link.process is not None and link.domain is not None
        starts.append(link.process.started_at)
        seen.append((time.monotonic(), link.process.node_pid, link.domain.domain_id))

    reported: list[str] = []
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(Ros2Link, "open", recording_open)
        results = run_suite(
            scenarios, "ros2", LinkOptions(), on_result=lambda r: reported.append(r.scenario)
        )
    assert [r.scenario for r in results] == names == reported  # in order
    assert all(r.ok for r in results), [r.first_failure for r in results]
    assert len({pid for _, pid, _ in seen}) == len(names)  # a fresh process each
    assert len({domain for _, _, domain in seen}) == len(names)  # its own domain each
    assert all(not alive(pid) for _, pid, _ in seen if pid)  # all stopped and reaped
    # Overlapped: the next scenarios' nodes were started before the first one was ready.
    assert starts[1] < seen[0][0] and starts[2] < seen[0][0]


def test_a_link_started_ahead_without_a_free_domain_starts_at_its_turn(monkeypatch) -> None:
    """No domain free when a link is started ahead (this machine's other runs hold them
    all) is not its scenario's failure: the link takes one when its scenario comes."""
    from harness.links import ros2
    from harness.ros.domain import NoFreeDomain

    calls: list[bool] = []  # True: refused

    def scarce(preferred=None):
        refuse = len(calls) == 1  # the first link started ahead
        calls.append(refuse)
        if refuse:
            raise NoFreeDomain("no free ROS domain id in 1..101: too many runs at once")
        return reserve_domain(preferred)

    monkeypatch.setattr(ros2, "reserve_domain", scarce)
    names = ["approach_wall", "out_of_range"]
    results = run_suite([resolve_scenario(n) for n in names], "ros2", LinkOptions())
    assert all(r.ok for r in results), [r.first_failure or r.error for r in results]
    assert calls == [False, True, False]  # refused ahead, taken at its turn


def test_a_start_not_awaited_reports_its_node_once_awaited() -> None:
    """`start(wait=False)` returns before the supervisor has said the node runs (a suite
    starts the next links meanwhile); `await_started` then waits for that word."""
    with started_node(wait=False) as process:
        process.await_started()
        assert process.node_pid is not None and alive(process.node_pid)
        process.await_started()  # again: nothing more to wait for


def test_a_start_awaited_after_its_bound_reads_the_report_that_came(monkeypatch) -> None:
    """A link started ahead is awaited when its scenario comes, which for a slow node is
    long after the start's bound (10 s) has passed since `start`: the report that came
    meanwhile is read first, and the bound counts from the wait (here it is none at all).
    """
    from harness.nodes import process as process_module

    monkeypatch.setattr(process_module, "START_WAIT_S", 0.0)
    with started_node(wait=False) as process:
        fd = process._status_fd
        assert fd is not None
        readable, _, _ = select.select([fd], [], [], 10.0)  # the reaper has reported
        assert readable
        process.await_started()
        assert process.node_pid is not None and alive(process.node_pid)


def test_a_node_that_cannot_start_is_reported_when_awaited(tmp_path: Path) -> None:
    """A start not awaited that fails (no such program) is a ConfigError naming it, raised
    by `await_started`, as `start` raises it when it waits."""
    missing = tmp_path / "no_such_node"
    process = NodeProcess(NodeCommand((str(missing),), description="no_such_node"), [], {})
    process.start(wait=False)
    try:
        with pytest.raises(ConfigError, match="cannot start no_such_node"):
            process.await_started()
    finally:
        process.stop()


def test_a_ctrl_c_as_the_reapers_pipe_closes_leaves_no_stale_descriptor(monkeypatch) -> None:
    """A KeyboardInterrupt that lands just after the reaper's pipe is closed must not
    leave its number behind: another pipe may take it, and the stop at exit then waited
    on a closed descriptor (EBADF, a traceback after Ctrl-C in run --watch)."""
    from harness.nodes import process as process_module

    node = NodeProcess(NodeCommand((sys.executable, "-c", "pass"), description="ends"), [], {})
    node.start()
    status_fd = node._status_fd
    closed = os.close

    def close_then_interrupt(fd: int) -> None:
        closed(fd)
        if fd == status_fd:
            raise KeyboardInterrupt

    monkeypatch.setattr(process_module.os, "close", close_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        node.stop()  # a link's close, when Ctrl-C comes
    monkeypatch.undo()
    assert node._status_fd is None
    node.stop()  # again, as at exit: nothing stale to wait on


THREADED = textwrap.dedent(
    """
    import threading
    import time
    from harness.nodes.command import reference_node, ros_arguments
    from harness.nodes.forkserver import ForkedSupervisor, _SERVERS
    from harness.nodes.process import NodeProcess
    from harness.ros.domain import discovery_environment, reserve_domain

    def one_node(said):
        domain = reserve_domain(None)
        env = {"ROS_DOMAIN_ID": str(domain.domain_id), **discovery_environment(network=False)}
        process = NodeProcess(reference_node(), ros_arguments(("threshold:=0.4",)), env)
        try:
            process.start()
            said.append(isinstance(process._popen, ForkedSupervisor))
            end = time.monotonic() + 15
            while "threshold 0.4 m" not in process.tail("stderr") and time.monotonic() < end:
                time.sleep(0.02)  # up and running: then a SIGINT ends it with 0
            said.append(process.stop())
        finally:
            domain.release()

    said = []
    for _ in range(2):  # a task thread that ends, then another, as a Dask worker's may
        thread = threading.Thread(target=one_node, args=(said,))
        thread.start()
        thread.join(60)
    servers = list(_SERVERS.values())
    print(said, len(servers), all(s._process.poll() is None for s in servers))
    """
)


def test_nodes_started_from_threads_that_end_are_forked_and_the_server_outlives_them() -> None:
    """A Dask worker runs each task in a thread: its nodes are forked too, from a server
    started by a thread that lasts (PDEATHSIG follows the starting thread)."""
    done = subprocess.run(
        [sys.executable, "-c", THREADED], capture_output=True, text=True, timeout=100
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["[True,", "0,", "True,", "0]", "1", "True"], done.stdout
