"""A student's build or node that failed because the sandbox refused it, told so (pure).

The failure's own text (the last error line colcon or the node printed) is
kept; what the sandbox refused is added in words a student can act on.
"""

from __future__ import annotations

import re

from harness.sandbox.limits import SandboxLimits

__all__ = ["refusal_of"]

_REFUSALS = (
    (
        re.compile(r"Read-only file system|EROFS", re.IGNORECASE),
        "the sandbox refused a write outside the student's own folders",
    ),
    (
        re.compile(
            r"Network is unreachable|ENETUNREACH|Connection refused|ECONNREFUSED|"
            r"Temporary failure in name resolution|Name or service not known",
            re.IGNORECASE,
        ),
        "the sandbox has no network beyond its own loopback",
    ),
    (
        re.compile(r"MemoryError|Cannot allocate memory|ENOMEM|std::bad_alloc"),
        "the sandbox's memory limit ({memory_mb} MB per process) was reached",
    ),
    (
        re.compile(r"Resource temporarily unavailable.*fork|BlockingIOError.*fork|EAGAIN"),
        "the sandbox's process limit ({processes}) was reached",
    ),
)


def refusal_of(text: str, limits: SandboxLimits) -> str | None:
    """What the sandbox (with `limits`) refused, if the failure `text` shows it; None
    otherwise."""
    for pattern, words in _REFUSALS:
        if pattern.search(text):
            return words.format(memory_mb=limits.memory_mb, processes=limits.processes)
    return None
