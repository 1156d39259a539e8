"""An audit of a suite from the cache, or run now: what ``grade`` warns with."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from harness.audit.cache import audit_key, cached_audit, keep_audit
from harness.audit.mutants import MUTANTS
from harness.audit.report import audit_json
from harness.audit.suite_audit import audit_suite
from harness.audit.task import AuditConfig

__all__ = ["known_audit", "survivors_warning"]


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


def survivors_warning(data: dict[str, Any], scenario_words: str) -> str | None:
    """One line naming the mistakes the suite lets pass, or None when it catches all."""
    survivors = [str(name) for name in data.get("survivors", [])]
    if not survivors:
        return None
    total = len(data.get("mutants", [])) or len(survivors)
    return (
        f"warning: these scenarios let {len(survivors)} of {total} typical mistakes pass: "
        f"{', '.join(survivors)} (fossbot-hil audit {scenario_words} shows what would "
        "catch them)"
    )
