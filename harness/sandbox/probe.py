"""Can this machine make the grader's sandboxes? Asked once per process, by trying.

A sandbox, and one nested in it (as a node's is), each run ``true``. The
answer is None (it works) or the reason with its fix, for ``grade``'s
one-line error and for a cluster worker's report.
"""

from __future__ import annotations

import functools
import shutil
import socket
import subprocess

from harness.option_names import named
from harness.sandbox.bwrap import bwrap_argv
from harness.sandbox.views import node_view, run_view

__all__ = ["sandbox_problem", "NO_SANDBOX_HINT"]

PROBE_TIMEOUT_S = 20.0
NO_SANDBOX_HINT = "or grade with {no_sandbox} (student code then runs with your rights)"
MISSING = (
    "grade runs each student's build and node in a bubblewrap sandbox, and bwrap is not "
    "installed{where}: install the bubblewrap package (apt install bubblewrap; dnf install "
    "bubblewrap), " + NO_SANDBOX_HINT
)
REFUSED = (
    "bwrap cannot make a sandbox{where}: {said} (user namespaces are off or restricted: "
    "on Ubuntu 23.10 and later AppArmor restricts them, see docs/grading.md), " + NO_SANDBOX_HINT
)


@functools.cache
def sandbox_problem() -> str | None:
    """None when bubblewrap works here, nested too; else why, with the fix."""
    where = f" on {socket.gethostname()}"
    bwrap = shutil.which("bwrap")
    if bwrap is None:
        return MISSING.format(where=where, no_sandbox=named("no_sandbox"))
    inner = bwrap_argv(node_view([]), ["true"], bwrap=bwrap)
    outer = bwrap_argv(run_view([], [], []), inner, bwrap=bwrap)
    try:
        done = subprocess.run(
            outer, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=PROBE_TIMEOUT_S
        )
    except (OSError, subprocess.TimeoutExpired) as err:
        return REFUSED.format(where=where, said=str(err), no_sandbox=named("no_sandbox"))
    if done.returncode != 0:
        said = (done.stderr.strip().splitlines() or [f"exit code {done.returncode}"])[-1]
        return REFUSED.format(where=where, said=said, no_sandbox=named("no_sandbox"))
    return None
