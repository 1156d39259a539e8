"""ROS domain reservations: automatic ids, and explicit ones (--domain-id) reserved the same way.

No ROS here: a reservation is a lock file per id. Ids outside the
automatic range 1..101 keep these tests out of the way of parallel runs.
"""

from __future__ import annotations

import select
import subprocess
import sys
import textwrap
from collections.abc import Iterator

import pytest

from harness.errors import ConfigError
from harness.holder_lock import held_here, take
from harness.ros.domain import lock_file, reserve_domain

pytestmark = pytest.mark.timeout(30)


def child(script: str, *args: str) -> subprocess.Popen[str]:
    """A Python child running `script`; it prints 'held' (or its answer) when ready."""
    return subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(script), *args],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def first_line(popen: subprocess.Popen[str]) -> str:
    assert popen.stdout is not None
    if not select.select([popen.stdout], [], [], 20)[0]:
        pytest.fail("the child said nothing")
    line = popen.stdout.readline()
    assert line, popen.stderr.read() if popen.stderr else ""
    return line.strip()


@pytest.fixture
def children() -> Iterator[list[subprocess.Popen[str]]]:
    started: list[subprocess.Popen[str]] = []
    yield started
    for popen in started:
        if popen.poll() is None:
            popen.kill()
        popen.wait(timeout=10)


EXPLICIT = """
import sys
from harness.ros.domain import reserve_domain
reservation = reserve_domain(int(sys.argv[1]))
print("held", flush=True)
sys.stdin.readline()
"""


@pytest.mark.parametrize("domain_id", [150, 232])
def test_an_explicit_id_another_run_holds_is_refused_naming_it(
    domain_id: int, children: list
) -> None:
    """Ids outside the automatic range are reserved too."""
    holder = child(EXPLICIT, str(domain_id))
    children.append(holder)
    assert first_line(holder) == "held"
    with pytest.raises(ConfigError) as refused:
        reserve_domain(domain_id)
    message = str(refused.value)
    assert message.startswith(f"ROS domain {domain_id} is in use by pid {holder.pid} (-c ")
    assert "would judge each other's messages" in message and "\n" not in message
    holder.stdin.close()
    holder.wait(timeout=10)
    take(lock_file(domain_id)).release()  # its holder gone, the id is free again


AUTOMATIC_SKIPS_EXPLICIT = """
import sys
import harness.ros.domain as domains
from harness.errors import LinkError
explicit = int(sys.argv[1])
held = domains.reserve_domain(explicit)
domains.FIRST_ID, domains.LAST_ID = explicit, explicit + 1
automatic = domains.reserve_domain()
try:
    domains.reserve_domain()
except LinkError:
    print(f"automatic {automatic.domain_id}, then none", flush=True)
"""


def test_automatic_reservations_never_hand_out_an_explicit_id_in_use() -> None:
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(AUTOMATIC_SKIPS_EXPLICIT), "160"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.stdout.strip() == "automatic 161, then none", done.stderr


def test_the_process_that_reserved_an_id_may_take_it_again() -> None:
    """The pytest plugin reserves a free id, then the link reserves it again by number."""
    with reserve_domain() as automatic:
        again = reserve_domain(automatic.domain_id)
        assert again.domain_id == automatic.domain_id
        again.release()
        assert held_here(lock_file(automatic.domain_id))  # the first still holds it
    take(lock_file(automatic.domain_id)).release()  # free once both let go


def test_an_explicit_id_is_free_again_once_its_run_lets_go() -> None:
    with reserve_domain(180) as explicit:
        assert explicit.domain_id == 180 and held_here(lock_file(180))
    assert not held_here(lock_file(180))
    take(lock_file(180)).release()


JOIN = """
import sys
from harness.ros.domain import reserve_domain
print(reserve_domain(int(sys.argv[1])).domain_id, flush=True)
"""


def test_a_run_started_by_the_holder_runs_in_its_reservation(children: list) -> None:
    """A test that reserved a domain for the board it simulates starts the harness in it."""
    domain_id = 170
    with take(lock_file(domain_id)):
        done = subprocess.run(
            [sys.executable, "-c", textwrap.dedent(JOIN), str(domain_id)],
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert done.returncode == 0 and done.stdout.strip() == str(domain_id), done.stderr
        # Started through a shell: the holder is its grandparent.
        shell = subprocess.run(
            ["sh", "-c", f'"{sys.executable}" -c "$0" {domain_id}', textwrap.dedent(JOIN)],
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert shell.returncode == 0 and shell.stdout.strip() == str(domain_id), shell.stderr
