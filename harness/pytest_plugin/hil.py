"""The ``hil`` fixture's object: run one scenario through a link and judge it.

The runner, PyBullet and rclpy are imported at the first ``hil.run``, never when
pytest loads the plugin; a bad argument fails the test with one line. Each run holds
its own domain (reserved here, so the result can name it) and its port, so parallel
workers and sessions never meet."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import pytest

from harness.errors import ConfigError, HarnessError
from harness.links.kinds import link_kind
from harness.option_names import speaking
from harness.pytest_plugin.cases import HilCase
from harness.pytest_plugin.result import HilResult
from harness.run_request.table import DEFAULT_PORT_WAIT_S, names

if TYPE_CHECKING:
    from harness.links.base import LinkOptions
    from harness.run_request import RunRequest
    from harness.scenario.schema import Scenario

    ScenarioRef = str | os.PathLike[str] | HilCase | Scenario
    Faults = str | Sequence[str | dict[str, Any]] | None

__all__ = ["Hil"]
#: LinkOptions fields the runner fills in itself, per scenario.
RUNNER_FIELDS = ("threshold", "scan_rate_hz")


def _run_names() -> dict[str, str]:
    """How a failure names hil.run's arguments: ``scan_topic=`` for the CLI's --scan-topic."""
    from harness.commands.node_names import CLI_NAMES

    return {field: f"{field}=" for field in CLI_NAMES}


def _request(options: LinkOptions, link: str, run: dict[str, Any]) -> RunRequest:
    """hil.run's arguments as the run request, checked once; ConfigError naming them by
    hil.run's keywords (``scan_timeout``, ``seed``)."""
    from harness.run_request import OptionError, RunRequest
    from harness.run_request.request import NODE_KEYS, link_keys

    # A link that runs no node ignores the session's node (hil.run's node keywords too).
    runs_node = link_kind(link).runs_node
    values = {k: getattr(options, k) for k in link_keys() if runs_node or k not in NODE_KEYS}
    try:
        return RunRequest.of({**values, **run, "link": link}, typed=True)
    except OptionError as err:
        raise ConfigError(err.render(names("run"), subject=True)) from None


def _fail(message: str) -> NoReturn:
    pytest.fail(f"hil.run: {message}", pytrace=False)


def _fault_list(faults: Faults) -> list[str | dict[str, Any]] | None:
    """A name, "a,b", or a list of names and inline fault mappings; checked now."""
    from harness.faults.sensor import build_profile, split_fault_text

    if faults is None:
        return None
    items: list[str | dict[str, Any]]
    if isinstance(faults, str):
        items = list(split_fault_text(faults))
    elif isinstance(faults, Sequence):
        items = list(faults)
    else:
        raise ConfigError(f"faults must be a name, 'a,b' or a list, got {faults!r}")
    build_profile(items, field_name="faults")
    return items


class Hil:
    """Run scenarios against the node under test; see docs/pytest.md."""

    def __init__(
        self,
        link: str,
        options: LinkOptions,
        *,
        seed: int | None = None,
        warning_when_clear: str | None = None,
        port_wait: float = DEFAULT_PORT_WAIT_S,
        base_dir: Path | None = None,
        record: Callable[[str, object], None] | None = None,
    ) -> None:
        self.link = link
        self.options = options
        self.seed = seed
        self.warning_when_clear = warning_when_clear
        self.port_wait = port_wait
        self.base_dir = base_dir  # relative scenario paths may be relative to the test file
        self.results: list[HilResult] = []
        self._record = record

    def __repr__(self) -> str:
        o = self.options
        node = o.node or (f"{o.package} {o.executable}" if o.package else None)
        what = f"node {node!r}" if node else "the reference node"
        if not link_kind(self.link).runs_node:
            what = f"processor {o.processor!r}" if o.processor else "the reference processing"
        return f"<hil: {self.link} link, {what}>"

    # -- arguments ----------------------------------------------------------
    def _scenario(self, ref: ScenarioRef) -> Scenario:
        from harness.scenario.files import resolve_scenario
        from harness.scenario.schema import Scenario

        if isinstance(ref, Scenario):
            return ref
        text = os.fspath(ref) if not isinstance(ref, HilCase) else ref.scenario
        if not isinstance(text, str):
            raise ConfigError(f"scenario must be a name or a path, got {ref!r}")
        candidate = Path(text)
        if (
            self.base_dir is not None
            and not candidate.is_absolute()
            and not candidate.exists()
            and (self.base_dir / candidate).is_file()
        ):
            text = str(self.base_dir / candidate)
        return resolve_scenario(text)

    def _options(self, link: str, overrides: dict[str, Any]) -> LinkOptions:
        names = [f.name for f in fields(self.options) if f.name not in RUNNER_FIELDS]
        for key in overrides:
            if key not in names:
                raise ConfigError(f"unknown option {key!r} (known: link, {', '.join(names)})")
        if "params" in overrides:
            params = overrides["params"]
            if isinstance(params, str) or not isinstance(params, (Sequence, set, frozenset)):
                got = repr(params)[:60]
                raise ConfigError(f"params must be a list of NAME:=VALUE items, got {got}")
            overrides = {**overrides, "params": tuple(params)}
        options = replace(self.options, **overrides)
        if not link_kind(link).serial_line and "port" not in overrides:
            options = replace(options, port=None)  # the board's port concerns board links only
        return options

    def _checked(
        self,
        scenario: ScenarioRef,
        threshold: float | None,
        faults: Faults,
        seed: int | None,
        link: str,
        status_regex: str | None,
        overrides: dict[str, Any],
        rule: str | None = None,
    ) -> tuple[Scenario, list[str | dict[str, Any]] | None, LinkOptions, RunRequest]:
        """The run's arguments, checked; ConfigError names the first bad one."""
        chosen = self._scenario(scenario)
        fault_items = _fault_list(faults)
        options = self._options(link, overrides)
        run = {"threshold": threshold, "seed": seed, "warning_when_clear": rule}
        request = _request(options, link, run)
        if status_regex is not None:
            from harness.judge.status import compile_status_pattern

            compile_status_pattern(status_regex)
        from harness.commands.node_names import checked_node_options

        numbers = {key: getattr(request, key) for key in ("scan_timeout", "ready_timeout")}
        options = checked_node_options(replace(options, **numbers), _run_names())
        return chosen, fault_items, options, request

    # -- running ------------------------------------------------------------
    def run(
        self,
        scenario: ScenarioRef,
        threshold: float | None = None,
        faults: Faults = None,
        seed: int | None = None,
        *,
        link: str | None = None,
        status_regex: str | None = None,
        warning_when_clear: str | None = None,
        **overrides: Any,
    ) -> HilResult:
        """Run one scenario (a shipped name, a file, or a ``hil_case``) and judge every tick;
        `threshold`, `faults`, `seed` and `warning_when_clear` override the scenario's,
        `overrides` are LinkOptions fields. Returns the result; it does not assert."""
        from harness.runner.settings import RunSettings

        given = [*overrides, *(["link"] if link is not None else [])]
        link = link if link is not None else self.link
        if isinstance(scenario, HilCase) and faults is None:
            faults = scenario.faults
        seed = seed if seed is not None else self.seed
        rule = warning_when_clear if warning_when_clear is not None else self.warning_when_clear
        try:
            chosen, fault_items, options, request = self._checked(
                scenario, threshold, faults, seed, link, status_regex, overrides, rule
            )
        except ConfigError as err:
            problem = str(err)  # failed outside the handler: no chained traceback
        else:
            problem = None
        if problem is not None:
            _fail(problem)
        settings = RunSettings(
            seed=request.seed,
            threshold=request.threshold,
            faults=fault_items,
            status_pattern=status_regex,
            warning_when_clear=request.warning_when_clear,
        )
        # The link's messages name the session's options --hil-node, hil.run's as keys: node.
        with speaking({k: name for k, name in names("hil").items() if k not in given}):
            result = self._run(chosen, link, options, settings)
        self.results.append(result)
        if self._record is not None:
            from harness.judge.verdicts import verdict_of

            verdict = verdict_of(result.raw)
            if result.failed_ticks:
                verdict += f" ({len(result.failed_ticks)} ticks)"
            self._record("hil", f"{result.scenario} over {link}: {verdict}")
        return result

    def _run(self, scenario: Scenario, link: str, options: LinkOptions, settings: Any) -> HilResult:
        from harness.runner.scenario_run import run

        kind = link_kind(link)
        physical = kind.serial_line and options.port is not None
        domain_id = options.domain_id
        try:
            with ExitStack() as held:
                if physical:
                    from harness.serial_line.port_lock import hold_port

                    assert options.port is not None
                    label = f"--hil-port {options.port}"
                    held.enter_context(hold_port(options.port, self.port_wait, label=label))
                elif kind.runs_node and domain_id is None:
                    from harness.ros.domain import reserve_domain

                    domain_id = held.enter_context(reserve_domain()).domain_id
                    options = replace(options, domain_id=domain_id)
                raw = run(scenario, link, options, settings)
        except HarnessError as err:  # ConfigError (node, link, port) or no free domain
            problem = str(err)
        else:
            return HilResult(raw, domain_id=domain_id if kind.runs_node else None)
        _fail(problem)
