"""Each scenario's run, decided once before anything starts: a `RunPlan`.

Deriving threshold, seed, faults, warning rule and link options where each
was used did it several times over, and a mistake in the fifth scenario's
overrides came after four were judged: planned up front, a usage error
comes before any node starts and every step reads the same values.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace

from harness.errors import ConfigError
from harness.faults.link import scan_periods
from harness.faults.sensor import FaultProfile
from harness.judge.oracle import Oracle
from harness.judge.records import RunResult
from harness.links.base import LinkOptions, link_class
from harness.option_names import named
from harness.runner.settings import (
    RunSettings,
    effective_seed,
    effective_threshold,
    fault_profile,
    warning_rule,
)
from harness.scenario.schema import Scenario


@dataclass(frozen=True)
class RunPlan:
    """One scenario's run through one link, with every value it is judged by."""

    scenario: Scenario
    link_name: str
    settings: RunSettings
    options: LinkOptions  # the link's, for this scenario (threshold, rate, topics)
    seed: int
    profile: FaultProfile
    warning_rule: str  # "required" or "optional"

    @property
    def threshold(self) -> float:
        return self.options.threshold

    def periods(self) -> Iterator[float] | None:
        """Seconds between scans where the fault profile drifts the rate, else None."""
        drift = self.profile.link.get("rate_drift")
        return scan_periods(drift, self.scenario.lidar_spec.rate_hz, self.seed) if drift else None

    def oracle(self) -> Oracle:
        """The oracle this run's ticks are judged by."""
        return Oracle(
            self.threshold,
            noise_sigma=self.profile.noise_sigma,
            status_pattern=self.settings.status_pattern,
            warning_required_when_clear=self.warning_rule == "required",
        )

    def result(self, **fields: object) -> RunResult:
        """The run's record, empty but for what the plan decided (and `fields`)."""
        return RunResult(
            scenario=self.scenario.name,
            link=self.link_name,
            seed=self.seed,
            threshold=self.threshold,
            faults=self.profile.name,
            noise_sigma=self.profile.noise_sigma,
            warning_rule=self.warning_rule,
            **fields,  # type: ignore[arg-type]
        )

    def not_started(self, reason: str, diagnostics: str) -> RunResult:
        """The record of this run when its link never came up."""
        return self.result(error=reason, diagnostics=diagnostics)


def plan_run(
    scenario: Scenario, link_name: str, options: LinkOptions, settings: RunSettings
) -> RunPlan:
    """One scenario's plan (ConfigError naming the scenario or the option at fault)."""
    return plan_suite([scenario], link_name, options, settings)[0]


def plan_suite(
    scenarios: Sequence[Scenario], link_name: str, options: LinkOptions, settings: RunSettings
) -> list[RunPlan]:
    """Every scenario's plan, in order; a serial link's device mount is decided once for
    the whole run (one device on one robot serves every scenario)."""
    cls = link_class(link_name)
    if cls.serial_line:
        options = run_mount(scenarios, options)
    return [
        plan_one(scenario, link_name, options, settings, sets_node_topics=cls.sets_node_topics)
        for scenario in scenarios
    ]


def plan_one(
    scenario: Scenario,
    link_name: str,
    options: LinkOptions,
    settings: RunSettings,
    *,
    sets_node_topics: bool = False,
) -> RunPlan:
    """One scenario's plan with `options` as they are (`plan_suite` decides the mount and
    whether the link sets the node's topics; a live session its own link)."""
    return RunPlan(
        scenario,
        link_name,
        settings,
        scenario_options(scenario, options, settings, sets_node_topics=sets_node_topics),
        effective_seed(scenario, settings),
        fault_profile(scenario, settings),
        warning_rule(scenario, settings),
    )


def scenario_options(
    scenario: Scenario,
    options: LinkOptions,
    settings: RunSettings,
    *,
    sets_node_topics: bool = False,
) -> LinkOptions:
    """The link options for one scenario: its threshold, its LIDAR's rate, whether a missed
    deadline ends it and, on a link that publishes the scans itself (`sets_node_topics`),
    the node's topics it names (`node_topic_options`)."""
    options = replace(
        options,
        threshold=effective_threshold(scenario, settings),
        scan_rate_hz=scenario.lidar_spec.rate_hz,
        late_ends_run=settings.stop_at_first_failure,
    )
    return node_topic_options(scenario, options) if sets_node_topics else options


def node_topic_options(scenario: Scenario, options: LinkOptions) -> LinkOptions:
    """`options` with the scenario's node_topics, each set through the node's topic
    parameter, when the run left the topics to the lab's defaults: a user who named
    topics or topic parameters of their own (a node with other names) keeps them."""
    wanted = scenario.node_topics
    if wanted is None:
        return options
    defaults, fields = LinkOptions(), ("scan_topic", "status_topic", "warning_topic")
    own_topics = any(getattr(options, f) != getattr(defaults, f) for f in fields)
    given = {item.split(":=", 1)[0] for item in options.params}
    if own_topics or given & set(options.topic_params):
        return options
    names = zip(options.topic_params, (wanted.scan, wanted.status, wanted.warning), strict=True)
    topics = dict(zip(fields, names, strict=True))  # field -> (its parameter, the topic)
    chosen = {field: topic for field, (_, topic) in topics.items() if topic is not None}
    params = tuple(f"{param}:={topic}" for param, topic in topics.values() if topic is not None)
    return replace(options, **chosen, params=(*options.params, *params))


def run_mount(scenarios: Sequence[Scenario], options: LinkOptions) -> LinkOptions:
    """`options` with the device's mount for the run: the option's, else what the robot
    model says. A serial link plays one device on one robot for the whole run, so the
    scenarios' models must agree (ConfigError naming the two when they do not)."""
    if options.lidar_mount is not None or not scenarios:
        return options
    from harness.scenario.mount import scenario_mount

    mounts = [(scenario_mount(s), s) for s in scenarios]
    mount, first = mounts[0]
    for other, scenario in mounts[1:]:
        if other != mount:
            raise ConfigError(
                f"{scenario.source}: its robot model mounts the LIDAR {other.describe()}, but "
                f"{first.source}'s {mount.describe()}; one device serves the whole run: "
                f"run them apart, or give {named('lidar_mount')}"
            )
    return replace(options, lidar_mount=mount)
