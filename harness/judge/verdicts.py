"""A scenario run's one verdict, for every command and report (pure).

Every command and report says PASS, FAIL, ERROR or NOT RUN by ``verdict_of``
(docs/contract.md says what each means); a verdict is a ``str`` too, so
tables and JSON written before read the same.
"""

from __future__ import annotations

from enum import Enum
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from harness.judge.records import RunResult

__all__ = ["RunVerdict", "verdict_of"]


class RunVerdict(str, Enum):
    """What became of one scenario run."""

    PASS = "PASS"  # every expectation held, and the run reached its last tick
    FAIL = "FAIL"  # an answer was wrong, missing or late
    ERROR = "ERROR"  # the run broke before any answer was judged wrong
    NOT_RUN = "NOT RUN"  # skipped

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)

    @property
    def passed(self) -> bool:
        return self is RunVerdict.PASS

    @classmethod
    def read(cls, text: object) -> RunVerdict:
        """A verdict as a table or worker wrote it (PASSED, FAILED too); else an ERROR."""
        word = str(text).strip().upper()
        word = {"PASSED": "PASS", "FAILED": "FAIL"}.get(word, word)
        try:
            return cls(word)
        except ValueError:
            return cls.ERROR


def verdict_of(result: RunResult) -> RunVerdict:
    """PASS, FAIL (a wrong or missing answer), ERROR (the run broke, nothing wrong) or NOT RUN."""
    if result.ok:
        return RunVerdict.PASS
    if result.not_run:
        return RunVerdict.NOT_RUN
    return RunVerdict.ERROR if result.broken else RunVerdict.FAIL
