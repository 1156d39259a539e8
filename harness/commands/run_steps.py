"""The steps `run` and `run --watch` share: the checked options and scenarios, the
report folder, and writing reports with file-system errors as usage errors."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any, TypeVar

from harness.commands.arguments import (
    check_link_options,
    check_output_file,
    check_status_regex,
    judging_settings,
    request_of,
    unchecked_link_options,
)
from harness.errors import ConfigError

if TYPE_CHECKING:  # imported when a run starts (the parser is built for any command)
    from harness.judge.records import RunResult
    from harness.links.base import LinkOptions
    from harness.report.outputs import ReportFolder
    from harness.runner.settings import RunSettings
    from harness.scenario.schema import Scenario

T = TypeVar("T")


def selected(names: Sequence[str]) -> list[Scenario]:
    """The named scenarios (all resolved before anything runs), or every shipped one."""
    from harness.scenario.files import resolve_scenario, shipped_scenarios

    return [resolve_scenario(n) for n in names] if names else shipped_scenarios()


def settings_from(args: argparse.Namespace) -> RunSettings:
    """The per-run overrides given on the command line."""
    return replace(judging_settings(args), gui=args.gui)


def open_report(out: str | None, *, animate: bool = False) -> ReportFolder | None:
    """The `--out` folder, created now so a bad path fails before anything runs."""
    if out is None:
        return None
    from harness.report.outputs import ReportFolder, artifact_writers

    try:
        return ReportFolder(out, artifact_writers(animate=animate))
    except ConfigError as err:
        raise ConfigError(f"--out {err}") from None


def scenario_of(scenarios: Sequence[Scenario]) -> Callable[[RunResult], Scenario | None]:
    """The scenario each result ran: results come in the order of `scenarios`, one each."""
    pending = iter(scenarios)

    def lookup(result: RunResult) -> Scenario | None:
        scenario = next(pending, None)
        return scenario if scenario is not None and scenario.name == result.scenario else None

    return lookup


def run_link(args: argparse.Namespace) -> str:
    """The run's link: the one typed, else the grading file's, else the default."""
    return request_of(args, check=False).link


def prepared(args: argparse.Namespace) -> tuple[str, LinkOptions, list[Scenario]]:
    """The link, checked link options and scenarios of a run, every check done before a report
    folder exists. The node's fork server (if any) starts first: it takes a while, in
    another process, while the checks run."""
    from harness.links.base import link_class

    link = run_link(args)
    link_class(link).prepare(unchecked_link_options(args))
    options = check_link_options(args)
    scenarios = selected(args.scenarios)
    check_output_file("--junit-xml", args.junit_xml)
    check_status_regex(args)
    from harness.runner.settings import check_settings

    check_settings(scenarios, settings_from(args))
    return link, options, scenarios


def write_report_file(option: str, writer: Callable[..., T], *args: Any, **kwargs: Any) -> T:
    """Run a report writer; a file system error is the user's to fix, in one line."""
    try:
        return writer(*args, **kwargs)
    except OSError as err:
        raise ConfigError(f"{option}: {err.strerror or err}") from None


def write_junit_file(path: str, results: Sequence[RunResult], report: ReportFolder | None) -> None:
    """`--junit-xml`: the run's verdicts, linking the report folder's files when there is one."""
    from harness.report.junit import write_junit

    artifacts = [s.paths for s in report.scenarios] if report is not None else None
    write_report_file(f"--junit-xml {path}", write_junit, path, results, artifacts=artifacts)
