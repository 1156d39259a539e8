"""A run whose ROS domain someone else is in says so, instead of blaming the node.

A node left running in a domain (by a harness that was killed, or started by
hand with that ROS_DOMAIN_ID) reads the run's scans and answers them too: the
node under test would seem to answer twice. The run names the stranger and
ends as the harness's problem; and a node whose harness was killed keeps its
domain reserved until it has been stopped, so no later run meets it.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from child_process import alive

from harness.errors import ConfigError
from harness.links.base import LinkOptions
from harness.nodes.command import reference_node, ros_arguments
from harness.nodes.process import FORK_SERVER_SETTING, NodeProcess
from harness.ros.domain import discovery_environment, reserve_domain
from harness.runner.scenario_run import run
from harness.runner.settings import RunSettings
from harness.scenario.files import parse_scenario

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

# Three minutes by a wall (1,800 scans, about 6 s in lockstep): the stranger, up before the
# run, must still discover the run's new participant, which took from 0 to 464 scans here
# (30 runs; 3 of 12 beyond approach_wall's 95). The run ends at the first scan it answers.
BY_A_WALL = {
    "description": "Stand 0.8 m from a wall for three minutes.",
    "lidar": {"preset": "gazebo"},
    "obstacles": [{"type": "wall", "start": [0.8, -2.0], "end": [0.8, 2.0], "thickness": 0.1}],
    "motion": {"segments": [{"until": {"duration": 180.0}}]},
    "threshold": 0.5,
}


def test_a_stranger_answering_the_scans_is_named() -> None:
    domain = reserve_domain(None)
    environment = {"ROS_DOMAIN_ID": str(domain.domain_id), **discovery_environment(network=False)}
    stranger = NodeProcess(reference_node(), ros_arguments(()), environment)
    try:
        stranger.start()
        # Up, as a node left running is: its topics made (its log line), or a loaded
        # machine can finish the short run before the stranger reads a scan.
        end = time.monotonic() + 30
        while "/scan -> /lidar_status" not in stranger.tail():
            assert time.monotonic() < end and stranger.returncode() is None, stranger.tail()
            time.sleep(0.05)  # bounded poll: until it logs its topics
        result = run(
            parse_scenario(BY_A_WALL),
            "ros2",
            LinkOptions(domain_id=domain.domain_id),
            RunSettings(),
        )
    finally:
        stranger.stop()
        domain.release()
    assert not result.ok
    assert result.error is not None, result.first_failure
    assert f"another ROS node shares this run's domain ({domain.domain_id})" in result.error
    assert "2 ROS participants publish /lidar_status (" in result.error, result.error


# A node slow to stop: it ignores SIGINT, so its supervisor needs SIGTERM, 2 s on.
SLOW_TO_STOP = """\
import pathlib, signal, sys, time
signal.signal(signal.SIGINT, signal.SIG_IGN)
pathlib.Path(sys.argv[0] + ".up").touch()
time.sleep(60)
"""

HARNESS_THAT_DIES = """\
import os, sys, time
from harness.nodes.command import shell_node
from harness.nodes.process import NodeProcess
from harness.ros.domain import reserve_domain
domain = reserve_domain(None)
node = NodeProcess(shell_node(f"{sys.executable} {sys.argv[1]}"), [], {}, held=domain.fileno())
node.start()
end = time.monotonic() + 20
while not os.path.exists(sys.argv[1] + ".up") and time.monotonic() < end:
    time.sleep(0.02)  # bounded poll: until it ignores SIGINT
print(domain.domain_id, node.node_pid, flush=True)
time.sleep(60)
"""


@pytest.mark.parametrize("forked", ["1", "0"], ids=["forked", "command"])
def test_a_killed_harness_leaves_its_domain_reserved_until_its_node_is_gone(
    tmp_path: Path, forked: str
) -> None:
    (tmp_path / "node.py").write_text(SLOW_TO_STOP)
    (tmp_path / "dying_harness.py").write_text(HARNESS_THAT_DIES)
    harness = subprocess.Popen(
        [sys.executable, str(tmp_path / "dying_harness.py"), str(tmp_path / "node.py")],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, FORK_SERVER_SETTING: forked},
    )
    assert harness.stdout is not None
    domain_id, node = (int(word) for word in harness.stdout.readline().split())
    harness.kill()
    harness.wait()
    assert alive(node)  # its supervisor gives it 2 s for SIGINT
    with pytest.raises(ConfigError, match=f"ROS domain {domain_id} is in use"):
        reserve_domain(domain_id)
    end = time.monotonic() + 20
    while alive(node) and time.monotonic() < end:
        time.sleep(0.05)  # bounded poll: SIGTERM after 2 s, SIGKILL after 3 s
    assert not alive(node)
    end = time.monotonic() + 5
    while True:  # its supervisor exits right after the node
        try:
            reserve_domain(domain_id).release()
            break
        except ConfigError:
            assert time.monotonic() < end, "the domain stayed reserved after the node was gone"
            time.sleep(0.05)
