"""JUnit XML: one test case per scenario, the oracle's explanation as the failure.

Properties name the run's settings, the explanation and the files written;
paths are relative to the XML file's folder, so a CI artifact keeps its
links. Every text is valid XML 1.0, harmless on a terminal and bounded (a
node's stderr may hold escape sequences or NUL).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path

from harness.atomic_write import relative_path, write_atomically
from harness.judge.records import RunResult
from harness.judge.verdicts import RunVerdict, verdict_of
from harness.safe_text import DIAGNOSTICS_LIMIT, TEXT_LIMIT, clip, for_xml

MAX_LISTED_FAILURES = 50


def _shown_path(path: Path, base: Path | None) -> str:
    return str(path.resolve()) if base is None else relative_path(path, base)


def _x(value: object, limit: int = TEXT_LIMIT) -> str:
    """Any value as XML-safe text, clipped to `limit` characters (its length noted)."""
    return for_xml(clip(str(value), limit))


def junit_xml(
    results: Sequence[RunResult],
    *,
    suite: str = "fossbot-hil",
    artifacts: Sequence[Mapping[str, Path]] | None = None,
    base: Path | None = None,
) -> bytes:
    """The report as bytes (CI reads `failure/@message` and the properties); `artifacts[i]`
    names `results[i]`'s files, `base` is the XML file's folder (None: absolute paths)."""
    if artifacts is not None and len(artifacts) != len(results):
        raise ValueError("junit_xml: one artifacts mapping per result")
    verdicts = [verdict_of(r) for r in results]  # the table's words: FAIL and ERROR as there
    failures = verdicts.count(RunVerdict.FAIL)
    errors = verdicts.count(RunVerdict.ERROR)
    root = ET.Element("testsuites")
    node = ET.SubElement(
        root,
        "testsuite",
        name=_x(suite),
        tests=str(len(results)),
        failures=str(failures),
        errors=str(errors),
        time=f"{sum(r.total_s for r in results):.3f}",
    )
    for i, r in enumerate(results):
        case = ET.SubElement(
            node,
            "testcase",
            classname=_x(f"{suite}.{r.link}"),
            name=_x(r.scenario),
            time=f"{r.total_s:.3f}",
        )
        props = ET.SubElement(case, "properties")
        for key, value in (
            ("link", r.link),
            ("seed", r.seed),
            ("threshold", r.threshold),
            ("faults", r.faults),
            ("ticks", len(r.records)),
            ("failed_ticks", len(r.failed_ticks)),
        ):
            ET.SubElement(props, "property", name=key, value=_x(value))
        first = _x(r.first_failure or "")
        if first:
            ET.SubElement(props, "property", name="explanation", value=first)
        for name, path in (artifacts[i] if artifacts is not None else {}).items():
            ET.SubElement(props, "property", name=_x(name), value=_x(_shown_path(path, base)))
        if r.ok:
            continue
        if r.not_run:
            ET.SubElement(case, "skipped", message=_x(r.error or "not run"))
            continue
        kind = "failure" if verdicts[i] is RunVerdict.FAIL else "error"
        lines = [_x(t.verdict.explanation) for t in r.failed_ticks[:MAX_LISTED_FAILURES]]
        if len(r.failed_ticks) > MAX_LISTED_FAILURES:
            lines.append(f"... and {len(r.failed_ticks) - MAX_LISTED_FAILURES} more failed ticks")
        if r.error:
            lines.append(_x(f"run ended: {r.error}"))
        if r.diagnostics:
            lines.append(_x(r.diagnostics, DIAGNOSTICS_LIMIT))
        ET.SubElement(case, kind, message=first, type=kind).text = "\n".join(lines)
    ET.indent(root)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True)


def write_junit(
    path: str | Path,
    results: Sequence[RunResult],
    *,
    artifacts: Sequence[Mapping[str, Path]] | None = None,
) -> Path:
    """Write atomically; artifact paths relative to the XML file's folder."""
    base = Path(path).resolve().parent
    return write_atomically(path, junit_xml(results, artifacts=artifacts, base=base))
