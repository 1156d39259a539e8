"""A shared-memory port that a killed process left half-made no longer hangs a domain.

Such a file (``/dev/shm/fastrtps_port<N>``, empty or never marked ready)
made every later participant of its domain wait forever: a node that never
became ready and ignored SIGTERM, a harness that hung its run. Reserving the
domain clears it.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from harness.ros.domain import discovery_environment, reserve_domain
from harness.ros.shm_ports import (
    ABANDONED_AFTER_S,
    READY,
    SHM_DIR,
    clear_half_made_ports,
    domain_ports,
)

NOW = 1_000_000.0
OLD = NOW - ABANDONED_AFTER_S - 1


def segment(folder: Path, port: int, content: bytes, mtime: float) -> Path:
    path = folder / f"fastrtps_port{port}"
    path.write_bytes(content)
    os.utime(path, (mtime, mtime))
    return path


def test_in_a_domain_of_its_own_the_harness_removes_every_port_not_marked_ready(
    tmp_path: Path,
) -> None:
    first = domain_ports(7)[0]
    empty = segment(tmp_path, first + 11, b"", NOW)
    unmarked = segment(tmp_path, first + 13, bytes(64), NOW)
    ready = segment(tmp_path, first + 15, READY + bytes(60), OLD)
    other_domain = segment(tmp_path, domain_ports(8)[0] + 11, b"", OLD)
    removed = clear_half_made_ports(7, shared=False, shm_dir=tmp_path, now=NOW)
    assert sorted(removed) == sorted([empty.name, unmarked.name])
    assert ready.exists() and other_domain.exists()


def test_in_a_named_domain_only_ports_long_empty_are_removed(tmp_path: Path) -> None:
    """Other programs may be making a port there, or mark theirs another way."""
    first = domain_ports(7)[0]
    long_empty = segment(tmp_path, first + 11, b"", OLD)
    being_made = segment(tmp_path, first + 13, b"", NOW - 1)
    marked_otherwise = segment(tmp_path, first + 15, bytes(64), OLD)
    removed = clear_half_made_ports(7, shared=True, shm_dir=tmp_path, now=NOW)
    assert removed == [long_empty.name]
    assert being_made.exists() and marked_otherwise.exists()


def test_a_domain_owns_the_rtps_port_range() -> None:
    assert domain_ports(0) == range(7400, 7650)
    assert domain_ports(79)[11] == 27161  # participant 0's user-traffic port


@pytest.mark.ros
@pytest.mark.timeout(60)
def test_a_node_starts_in_a_domain_a_killed_process_left_a_half_made_port_in() -> None:
    """The node's participant takes the port (participant 0's user traffic); before the
    fix it waited on the empty file forever and never reached its own checks."""
    free = reserve_domain()  # a free id, released and then poisoned
    domain_id = free.domain_id
    free.release()
    port = segment(SHM_DIR, domain_ports(domain_id)[11], b"", time.time() - 60)
    try:
        with reserve_domain(domain_id):
            assert not port.exists()
            node = subprocess.run(
                [sys.executable, "-m", "harness.reference.lidar_node"]
                + ["--ros-args", "-p", "threshold:=.nan"],
                env={
                    **os.environ,
                    "ROS_DOMAIN_ID": str(domain_id),
                    **discovery_environment(network=False),
                },
                capture_output=True,
                text=True,
                timeout=45,
            )
        assert node.returncode == 2, node.stderr
        assert "threshold" in node.stderr
    finally:
        port.unlink(missing_ok=True)
