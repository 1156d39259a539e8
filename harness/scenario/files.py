"""From a name or a file to a checked Scenario: parse, load, look up the shipped ones."""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from harness.errors import ConfigError, one_line
from harness.faults.sensor import build_profile
from harness.safe_text import shown
from harness.scenario.checks import (
    check_lidar_fits,
    check_model_files,
    check_reachable,
    check_run_length,
    check_start_clear,
)
from harness.scenario.limits import MAX_FILE_BYTES
from harness.scenario.model_files import exists
from harness.scenario.schema import Scenario, first_error
from harness.scenario.yaml_loader import load_yaml, yaml_problem
from harness.text_file import read_text_file

SCENARIO_SUFFIXES = (".yaml", ".yml")


def parse_scenario(data: Any, *, source: str = "<scenario>") -> Scenario:
    """Validate loaded YAML data (schema, bounds, cost); ConfigError names the source and field.

    Its model files are ``check_model_files``'s (``load_scenario_file`` does both).
    """
    where = shown(source)
    if not isinstance(data, dict):
        got = {type(None): "nothing (an empty file?)", list: "a list", str: "text"}.get(
            type(data), type(data).__name__
        )
        raise ConfigError(f"{where}: a scenario must be a mapping of fields, got {got}")
    if "source" in data:  # the harness's own field: where the file is, never the file's say
        raise ConfigError(f"{where}: source: unknown key")
    try:
        scenario = Scenario.model_validate({**data, "source": source})
        scenario.lidar.spec()
    except ValidationError as err:
        raise ConfigError(f"{where}: {first_error(err)}") from None
    except ConfigError as err:
        raise ConfigError(f"{where}: lidar: {err}") from None
    except RecursionError:
        raise ConfigError(f"{where}: nested too deeply (or refers to itself)") from None
    try:
        check_run_length(scenario, build_profile(scenario.faults))
        check_lidar_fits(scenario)
    except ConfigError as err:
        raise ConfigError(f"{where}: {err}") from None
    if not scenario.name:
        scenario = scenario.model_copy(update={"name": Path(source).stem[:100]})
    return scenario


def load_scenario_file(path: str | Path) -> Scenario:
    """Read and validate one scenario file, and the model files it names."""
    path = Path(path)
    name = shown(str(path))
    # a regular file, at most MAX_FILE_BYTES, UTF-8; never blocks on a FIFO
    text = read_text_file(path, limit=MAX_FILE_BYTES, name=name, kind="scenario file")
    try:
        data = load_yaml(text)
    except yaml.YAMLError as err:
        raise ConfigError(f"{name}: {yaml_problem(err)}") from None
    except RecursionError:
        raise ConfigError(f"{name}: YAML error: nested too deeply") from None
    except ValueError as err:  # e.g. an integer with more digits than Python converts
        raise ConfigError(f"{name}: YAML error: {one_line(err)}") from None
    return checked_scenario(data, source=str(path))


def checked_scenario(data: Any, *, source: str) -> Scenario:
    """`parse_scenario`, then the checks that read model files or span fields."""
    scenario = parse_scenario(data, source=source)
    check_reachable(scenario)
    check_start_clear(scenario, check_model_files(scenario))
    return scenario


def shipped_dir() -> Path:
    """Folder of the scenarios installed with the harness."""
    return Path(str(resources.files("harness.scenarios")))


def shipped_scenarios() -> list[Scenario]:
    """Every shipped scenario, sorted by name."""
    files = sorted(p for p in shipped_dir().iterdir() if p.suffix in SCENARIO_SUFFIXES)
    return sorted((load_scenario_file(p) for p in files), key=lambda s: s.name)


def resolve_scenario(ref: str) -> Scenario:
    """A shipped scenario name or a path to a scenario file."""
    candidate = Path(ref)
    named = candidate.suffix in SCENARIO_SUFFIXES or "/" in ref
    if named or exists(candidate, follow_symlinks=True):
        return load_scenario_file(candidate)
    for suffix in SCENARIO_SUFFIXES:
        shipped = shipped_dir() / f"{ref}{suffix}"
        if exists(shipped, follow_symlinks=True):
            return load_scenario_file(shipped)
    known = ", ".join(s.name for s in shipped_scenarios())
    raise ConfigError(f"unknown scenario {ref[:100]!r} (shipped: {known}; or give a .yaml path)")
