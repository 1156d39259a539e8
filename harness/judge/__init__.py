"""How an answer is judged: the node's words read, held against the truth, recorded.

- ``answers``: what came back for one scan (status Strings, warning Bools);
- ``status``: reading the free-text status a student node publishes (its
  numbers and their labels in ``status_numbers``); a structured one (JSON,
  a printed dict, ``key: value`` lines) taken apart by ``structured_text``
  and read by its keys in ``structured_status``;
- ``run_hints``: what a whole run suggests about a failure's cause;
- ``oracle``: per-tick expectations from the scan the node was sent, and
  the verdict with its explanation;
- ``records``: what one run produced, tick by tick (``RunResult``);
- ``verdicts``: its one verdict (``RunVerdict``: PASS, FAIL, ERROR, NOT RUN;
  ``verdict_of``), as every command and report says it;
- ``alignment``: whether the board's /scan is the truth turned or mirrored,
  fitted over a run (``run_alignment``), and the likely fix;
- ``reading_coverage``: which kinds of readings a suite's delivered scans
  carry (``coverage_of``), and what it never delivers (``gaps``).

Pure: numpy only, no rclpy, no pybullet. Add a check to the ``Oracle``; teach
``status`` a new way students write their status.
"""

from harness import lazy_exports

_EXPORTS = {
    "Answers": "answers",
    "Received": "answers",
    "StatusClaim": "status",
    "parse_status": "status",
    "Oracle": "oracle",
    "Verdict": "oracle",
    "RunResult": "records",
    "TickRecord": "records",
    "RunVerdict": "verdicts",
    "verdict_of": "verdicts",
    "Alignment": "alignment",
    "fit_alignment": "alignment",
    "run_alignment": "alignment",
    "ReadingCoverage": "reading_coverage",
    "coverage_of": "reading_coverage",
    "coverage_by_scenario": "reading_coverage",
    "gaps": "reading_coverage",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
