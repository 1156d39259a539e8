"""``@pytest.mark.hil_scenarios``: one test per scenario and fault profile.

``hil_scenarios("approach_wall", "out_of_range", faults=["clean", "noisy"])`` gives
``hil_case`` four cases (ids ``approach_wall-clean`` ...); no names: every shipped
scenario; no ``faults``: each one's own profile. Checked at collection, so a typo is
one collection error, not N failures."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from harness.errors import ConfigError

__all__ = ["MARKER", "MARKER_HELP", "HilCase", "cases_from_marker"]

MARKER = "hil_scenarios"
MARKER_HELP = (
    f"{MARKER}(*names, faults=None): run the test once per scenario (default: every "
    "shipped one) and fault profile, as its hil_case argument"
)


@dataclass(frozen=True)
class HilCase:
    """One scenario (a shipped name or a file path) with a fault override (None: its own)."""

    scenario: str
    faults: str | None = None

    @property
    def id(self) -> str:
        name = Path(self.scenario).stem if "/" in self.scenario else self.scenario
        return name if self.faults is None else f"{name}-{self.faults}"

    def __str__(self) -> str:
        return self.id


def _fault_items(faults: Any) -> list[str | None]:
    if faults is None:
        return [None]
    if isinstance(faults, str):
        return [faults]
    if isinstance(faults, Sequence) and faults and all(isinstance(f, str) for f in faults):
        return list(faults)
    raise ConfigError(
        f"faults= must be a profile name or a list of them (e.g. ['clean', 'noisy']), "
        f"got {faults!r}"
    )


def cases_from_marker(args: Sequence[Any], kwargs: dict[str, Any]) -> list[HilCase]:
    """The cases a marker names, checked: unknown names raise ConfigError (one line)."""
    from harness.faults.sensor import build_profile, split_fault_text
    from harness.scenario.files import resolve_scenario, shipped_scenarios

    unknown = sorted(set(kwargs) - {"faults"})
    if unknown:
        raise ConfigError(f"unknown argument {unknown[0]!r} (known: faults)")
    for name in args:
        if not isinstance(name, str):
            raise ConfigError(f"scenario names must be strings, got {name!r}")
        resolve_scenario(name)
    names = list(args) or [s.name for s in shipped_scenarios()]
    faults = _fault_items(kwargs.get("faults"))
    for item in faults:
        if item is not None:
            build_profile(split_fault_text(item), field_name="faults")
    return [HilCase(name, item) for name in names for item in faults]
