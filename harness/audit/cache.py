"""Audits kept in the user's cache, so grading the same suite again costs nothing.

The key hashes all the outcome depends on: each scenario's content (not its
name), how it is judged, the seeds, the mistake library and the harness's
version. A cached audit is only a shortcut: anything unreadable is a miss.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from harness.atomic_write import write_atomically
from harness.audit.mutants import NODE_SCRIPT
from harness.audit.task import AuditConfig
from harness.user_cache import cache_root

__all__ = ["audit_key", "cached_audit", "keep_audit"]

FORMAT = 2  # 2: each mutant's status and error, the score of the mutants judged


def _folder() -> Path:
    return cache_root() / "audit"


def audit_key(config: AuditConfig, scenarios: Sequence[Any], mutants: Sequence[str]) -> str:
    """The hash that names an audit: the suite's content, its judging and the library."""
    from harness import __version__

    described = {
        "format": FORMAT,
        "version": __version__,
        "scenarios": [s.model_dump(mode="json") for s in scenarios],
        "link": config.link,
        "options": {k: v for k, v in asdict(config.options).items() if k != "node"},
        "settings": asdict(config.settings),
        "seeds": list(config.seeds),
        "mutants": list(mutants),
        "library": hashlib.sha256(NODE_SCRIPT.read_bytes()).hexdigest(),
    }
    text = json.dumps(described, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def cached_audit(key: str) -> dict[str, Any] | None:
    """The audit's JSON object kept under `key`, or None."""
    try:
        data = json.loads((_folder() / f"{key}.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not isinstance(data.get("survivors"), list):
        return None
    return data


def keep_audit(key: str, data: dict[str, Any]) -> None:
    """Keep the audit's JSON under `key`; a cache that cannot be written is no error."""
    with contextlib.suppress(OSError):
        _folder().mkdir(parents=True, exist_ok=True)
        write_atomically(_folder() / f"{key}.json", json.dumps(data, indent=2).encode())
