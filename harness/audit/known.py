"""An audit of a suite from the cache, or run now: what ``grade`` warns with."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from harness.audit.cache import audit_key, cached_audit, keep_audit
from harness.audit.matrix import CONTROL_NOT_RUN
from harness.audit.mutants import CONTROL, MUTANTS
from harness.audit.report import audit_json
from harness.audit.suite_audit import audit_suite
from harness.audit.task import AuditConfig

__all__ = ["audit_warning", "known_audit"]

REASON_CHARS = 200  # of each reason the warning gives


def known_audit(
    client: Any, config: AuditConfig, scenarios: Sequence[Any]
) -> tuple[dict[str, Any], bool]:
    """(the audit's JSON object, whether it came from the cache) of the whole library
    through `scenarios` judged as `config` says; run on `client` when not cached."""
    names = [m.name for m in MUTANTS]
    key = audit_key(config, scenarios, names)
    found = cached_audit(key)
    if found is not None:
        return found, True
    outcome = audit_suite(client, config, names)
    data = audit_json(outcome, repeat=len(config.seeds), seeds=list(config.seeds))
    if not outcome.matrix.unit_errors:  # an audit cut short is not one to keep
        keep_audit(key, data)
    return data, False


def audit_warning(data: dict[str, Any], scenario_words: str) -> str | None:
    """One line: what the audit could not run and why, and the mistakes that ran and that
    the suite lets pass; None when it ran everything and catches all. A mistake that could
    not run is never said to pass."""
    survivors = [str(name) for name in data.get("survivors", [])]
    could_not = _could_not_run(data)
    hint = f"(fossbot-hil audit {scenario_words} shows what would catch them)"
    if not could_not:
        if not survivors:
            return None
        total = len(data.get("mutants", [])) or len(survivors)
        return (
            f"warning: these scenarios let {len(survivors)} of {total} typical mistakes pass: "
            f"{', '.join(survivors)} {hint}"
        )
    line = f"warning: the audit could not run: {could_not}"
    judged = [m for m in data.get("mutants", []) if m.get("status") in ("killed", "survived")]
    if survivors:
        return (
            f"{line}; of the {len(judged)} typical mistakes that ran, these scenarios let "
            f"{len(survivors)} pass: {', '.join(survivors)} {hint}"
        )
    if judged:
        return f"{line}; these scenarios catch the {len(judged)} typical mistakes that ran"
    return line


def _could_not_run(data: dict[str, Any]) -> str:
    """What the audit could not run, grouped by why ('' when it ran everything): the
    correct node first, then the mistakes."""
    errors = {str(k): v for k, v in dict(data.get("unit_errors") or {}).items()}
    parts = []
    if CONTROL in errors:
        parts.append(f"the correct node: {_short(errors.pop(CONTROL))}")
    elif data.get("correct_node_not_run"):
        unjudged = [str(s) for s in data["correct_node_not_run"]]
        why = (data.get("correct_node_failed") or {}).get(unjudged[0], "")
        parts.append(f"the correct node in {', '.join(unjudged)}: {_short(why)}")
    by_why: dict[str, list[str]] = {}
    unjudged_only = []
    for name, why in errors.items():
        if str(why).endswith(CONTROL_NOT_RUN):
            unjudged_only.append(name)
        else:
            by_why.setdefault(_short(why), []).append(name)
    parts.extend(f"{', '.join(names)}: {why}" for why, names in by_why.items())
    if unjudged_only:
        parts.append(
            f"{', '.join(unjudged_only)}: failed only where the correct node could not run"
        )
    return "; ".join(parts)


def _short(why: object) -> str:
    """A reason on one line, at most REASON_CHARS long."""
    text = " ".join(str(why).split())
    return text if len(text) <= REASON_CHARS else text[: REASON_CHARS - 1] + "…"
