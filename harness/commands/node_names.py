"""ROS 2 names and parameters the harness passes a node, checked once for every caller.

The CLI, the pytest plugin and the grading file each name the options in
their own way (``--scan-topic``, ``scan_topic=``): the checks take those
names as `names` (``CLI_NAMES`` by default), so a message says what the
user typed. The rules for ROS 2 names themselves live in harness.ros.names.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import replace

from harness.errors import ConfigError
from harness.links.base import LinkOptions
from harness.ros.names import (
    InvalidName,
    check_parameter_name,
    check_parameter_rule,
    parameter_target,
    resolve_topic,
    shown_name,
)
from harness.run_request.table import names as option_names

TOPIC_FIELDS = ("scan_topic", "status_topic", "warning_topic")
#: How the command line names each option these checks name (the run request's table's
#: flags, with the separator before the value); the plugin passes its own (``scan_topic=``).
CLI_NAMES: Mapping[str, str] = {
    key: f"{option_names('cli')[key]} "
    for key in (*TOPIC_FIELDS, "params", "threshold_param", "threshold")
}


def topic_option(label: str, value: object) -> str:
    """A topic option's value, fully qualified; ConfigError names `label` and says why not."""
    try:
        return resolve_topic(value)  # type: ignore[arg-type] - resolve_topic checks the type
    except InvalidName as err:
        shown_value = shown_name(value) if isinstance(value, str) else repr(value)[:60]
        raise ConfigError(f"{label}{shown_value}: {err}") from None


def check_parameters(
    params: Iterable[str], threshold_param: str | None, names: Mapping[str, str] = CLI_NAMES
) -> None:
    """Parameter items that ROS 2 parses, each set once, none setting the threshold parameter.

    The harness passes the threshold to the node itself (``-p
    <threshold_param>:=<threshold>``, from --threshold or the scenario), and
    the oracle judges with that same threshold: a --param setting it too
    would make the node and the oracle disagree. A parameter given twice
    is refused, not warned about: ROS 2 silently keeps the last, and a
    test whose meaning depends on the order of its options is a mistake
    waiting to be made.
    """
    label = names["params"]
    if threshold_param:
        try:
            check_parameter_name(threshold_param)
        except InvalidName as err:
            option = names["threshold_param"]
            raise ConfigError(f"{option}{shown_name(threshold_param)}: {err}") from None
    threshold_name = parameter_target(f"{threshold_param}:=") if threshold_param else None
    seen: dict[tuple[str, str], str] = {}
    for rule in params:
        try:
            check_parameter_rule(rule)
        except InvalidName as err:
            raise ConfigError(f"{label.rstrip(' =')}: {err}") from None
        target = parameter_target(rule)
        if target in seen:
            raise ConfigError(
                f"{label}{shown_name(seen[target])} and {label}{shown_name(rule)} set the same "
                "parameter: ROS 2 would silently keep the last; give it once"
            )
        seen[target] = rule
        if target[1] == "use_sim_time":
            raise ConfigError(
                f"{label}{shown_name(rule)} sets use_sim_time, which the harness passes itself "
                "(true: the node's time is the harness's /clock, the simulated time of "
                "each scan); leave it out"
            )
        if threshold_name is not None and target[1] == threshold_name[1]:
            value = rule.partition(":=")[2]
            threshold = names["threshold"]
            raise ConfigError(
                f"{label}{shown_name(rule)} sets {target[1]!r}, the parameter the harness passes "
                f"the threshold in ({threshold.rstrip(' =')}, default the scenario's): the node "
                f"and the oracle would disagree; use {threshold}{value.strip()} instead "
                f"(or {names['threshold_param']}'' if the node must not get the threshold)"
            )


def checked_node_options(options: LinkOptions, names: Mapping[str, str] = CLI_NAMES) -> LinkOptions:
    """`options` with fully qualified topics; ConfigError naming the option (as `names`
    calls it) for a name ROS 2 refuses, two topics that are one (``scan`` is ``/scan``),
    or a parameter `check_parameters` refuses."""
    topics = {field: topic_option(names[field], getattr(options, field)) for field in TOPIC_FIELDS}
    first_with: dict[str, str] = {}
    for field, topic in topics.items():
        if topic in first_with:
            other = first_with[topic]
            raise ConfigError(
                f"{names[field]}{shown_name(getattr(options, field))}: the same topic as "
                f"{names[other]}{shown_name(getattr(options, other))} ({topic}); the scan, the "
                "status and the warning need a topic each"
            )
        first_with[topic] = field
    check_parameters(options.params, options.threshold_param, names)
    return replace(options, **topics)
