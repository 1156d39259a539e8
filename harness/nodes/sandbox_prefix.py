"""How a judging process in a sandbox starts its node: the nested sandbox's command, from
the environment the grader set (absent outside a sandbox)."""

from __future__ import annotations

import json
import os

__all__ = ["NODE_SANDBOX_ENV", "node_sandbox_prefix", "parent_for"]

NODE_SANDBOX_ENV = "FOSSBOT_HIL_NODE_SANDBOX"


def node_sandbox_prefix() -> list[str]:
    """The argv that goes before a node's start command; [] outside a sandbox."""
    text = os.environ.get(NODE_SANDBOX_ENV)
    if not text:
        return []
    prefix = json.loads(text)
    if not (isinstance(prefix, list) and all(isinstance(x, str) for x in prefix)):
        raise ValueError(f"{NODE_SANDBOX_ENV} must be a JSON list of strings")
    return prefix


def parent_for(prefix: list[str]) -> str:
    """The parent pid a started helper checks (its PDEATHSIG race): ours, or 0 when the
    sandbox's launcher stands between us (the helper then takes its own parent)."""
    return "0" if prefix else str(os.getpid())
