"""`grade`'s audit of its scenarios: which typical mistakes they let pass (harness.audit),
from the user's cache or run on the class's cluster once the class is graded."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rich.console import Console

from harness.errors import one_line
from harness.report.console_text import print_safe as say

if TYPE_CHECKING:
    from harness.grading.grade import GradeConfig
    from harness.scenario.schema import Scenario

__all__ = ["class_audit"]


def class_audit(
    console: Console, client: object, scenarios: list[Scenario], config: GradeConfig, out: Path
) -> str | None:
    """Which typical mistakes these scenarios let pass (harness.audit), from the cache or
    run now on the class's cluster; the warning line naming them, or None. An audit that
    cannot be made is said, never a reason to fail the grading."""
    import json
    from dataclasses import replace

    from harness.atomic_write import write_atomically
    from harness.audit.known import audit_warning, known_audit
    from harness.audit.task import AuditConfig

    audit = AuditConfig(
        scenarios=config.scenarios,
        scenario_refs=config.scenario_refs,
        link=config.link,
        options=replace(config.options, node=None, package=None, executable=None),
        settings=config.settings,
        seeds=(config.settings.seed,),
        units_dir=out.resolve() / "audit",
    )
    say(console, "checking which typical mistakes these scenarios catch (fossbot-hil audit)...")
    try:
        data, cached = known_audit(client, audit, scenarios)
    except Exception as err:  # noqa: BLE001 - the grades are written; the audit is advice
        return f"warning: the audit could not run: {type(err).__name__}: {one_line(err)}"
    write_atomically(out / "audit.json", json.dumps(data, indent=2).encode())
    words = " ".join(_scenario_words(scenarios))
    warning = audit_warning(data, words)
    if warning is None:
        killed = len(data.get("mutants", []))
        return f"these scenarios catch all {killed} typical mistakes{' (cached)' if cached else ''}"
    return warning


def _scenario_words(scenarios: list[Scenario]) -> list[str]:
    """How a command line names each scenario: a shipped one by name, others by file."""
    import shlex

    from harness.scenario.files import shipped_dir

    shipped = shipped_dir().resolve()
    return [
        s.name
        if not s.source or Path(s.source).resolve().parent == shipped
        else shlex.quote(s.source)
        for s in scenarios
    ]
