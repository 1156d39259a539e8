"""The grading worker starts its students' fork server (warm_python) before its own
imports, so the two run side by side: a real server, the one the suite then uses."""

from __future__ import annotations

import subprocess
import sys

import pytest

from harness.grading.worker import warm_node_server
from harness.nodes import forkserver
from harness.nodes.python_script import SERVER_MODULE

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]


def test_a_ros2_job_starts_the_node_server_the_suite_will_use() -> None:
    forkserver.close_all()
    try:
        assert warm_node_server({"link": "ros2"}) is True
        server = forkserver._SERVERS[SERVER_MODULE]
        assert server.ready()  # up, its modules imported: what the first node forks from
        assert forkserver.shared(SERVER_MODULE) is server  # the suite's start finds it
    finally:
        forkserver.close_all()


@pytest.mark.parametrize(
    ("job", "env"),
    [({"link": "inprocess"}, "1"), ({"link": "rplidar"}, "1"), ({"link": "ros2"}, "0")],
)
def test_no_server_for_other_links_or_when_fork_starts_are_off(
    job: dict[str, str], env: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    forkserver.close_all()
    monkeypatch.setenv("FOSSBOT_HIL_FORK_SERVER", env)
    assert warm_node_server(job) is False
    assert SERVER_MODULE not in forkserver._SERVERS


def test_the_worker_module_imports_neither_numpy_nor_the_runner() -> None:
    """What runs before the server starts: the worker's own module, kept light."""
    code = (
        "import sys, harness.grading.worker; "
        "print(sorted(m for m in ('numpy', 'harness.runner.suite', 'rclpy') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.stdout.strip() == "[]", done.stderr
