"""How an answer is judged: the node's words read, held against the truth, recorded.

One module per step (docs/architecture.md lists them): ``status`` reads
what the node said, ``oracle`` judges a tick, ``records`` keeps a run,
``verdicts`` gives its one verdict. Pure: numpy only, no rclpy, no pybullet.
Add a check to the ``Oracle``; teach ``status`` a new way students write.
"""

from harness import lazy_exports

_EXPORTS = {
    "Answers": "answers", "Received": "answers",
    "StatusClaim": "status", "parse_status": "status",
    "Oracle": "oracle", "Verdict": "oracle",
    "RunResult": "records", "TickRecord": "records",
    "RunVerdict": "verdicts", "verdict_of": "verdicts",
    "Alignment": "alignment", "fit_alignment": "alignment", "run_alignment": "alignment",
    "ReadingCoverage": "reading_coverage", "coverage_of": "reading_coverage",
    "coverage_by_scenario": "reading_coverage", "gaps": "reading_coverage",
}  # fmt: skip
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
