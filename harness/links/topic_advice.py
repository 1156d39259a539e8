"""Which topics a node under test uses instead of the harness's, and what to tell its user.

Read from the ROS graph (the harness's own node is passed in); nothing here waits long."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from harness.option_names import named

if TYPE_CHECKING:
    from harness.links.base import LinkOptions

SCAN_TYPE = "sensor_msgs/msg/LaserScan"
STRING_TYPE = "std_msgs/msg/String"
BOOL_TYPE = "std_msgs/msg/Bool"
# While not ready: once the graph shows the node reading LaserScans (or writing Strings) on
# another topic instead of the harness's, it is given this long to use ours too, then the
# run says so (waiting out the whole readiness bound would tell nothing more).
ELSEWHERE_GRACE_S = 1.0
LOOK_EVERY_S = 0.05  # a graph query costs more than a spin


def topics_elsewhere(node: Any, type_name: str, topic: str, *, publishers: bool) -> list[str]:
    """Topics other than `topic` that a node other than the harness's `node` publishes (or
    subscribes to) as `type_name`: where a node with another topic name sends (or reads) it."""
    me = (node.get_name(), node.get_namespace())
    get = node.get_publishers_info_by_topic if publishers else node.get_subscriptions_info_by_topic
    found = []
    for name, types in node.get_topic_names_and_types():
        if name == topic or type_name not in types:
            continue
        if any((i.node_name, i.node_namespace) != me for i in get(name)):
            found.append(name)
    return sorted(found)


def topic_hints(node: Any, options: LinkOptions, *, reads: bool, publishes: bool) -> str:
    """For a node never ready: the scan or status topic it uses instead, and the option
    that names it ('' when there is none to name)."""
    hints = []
    scan = (SCAN_TYPE, options.scan_topic, "scan_topic", "subscribes to a LaserScan", False)
    status = (STRING_TYPE, options.status_topic, "status_topic", "publishes a String", True)
    for missing, (type_name, topic, option, what, publishers) in (
        (not reads, scan),
        (not publishes, status),
    ):
        if not missing:
            continue
        others = topics_elsewhere(node, type_name, topic, publishers=publishers)
        if len(others) == 1:
            hints.append(
                f"it {what} on {others[0]}, not {topic}: pass {named(option)} {others[0]} "
                "if that is the lab's name"
            )
    return "".join(f"; {h}" for h in hints)


def untaken_topic_parameter(
    options: LinkOptions, parameter: str, topic: str, ask: Callable[[], tuple[str, list[str]] | str]
) -> str | None:
    """The rest of a note when the harness set the node's topic through `parameter` (a
    scenario's node_topics) and the node does not declare it, naming a parameter of its
    own that looks like it; else None. `ask` gives (node name, its parameters) or why not."""
    if f"{parameter}:={topic}" not in options.params:
        return None
    asked = ask()
    if isinstance(asked, str):
        return None  # its parameters are not known: the plain advice stands
    _, declared = asked
    if parameter in declared:
        return None
    word = parameter.split("_")[0]  # "warning", "lidar"
    own = [name for name in declared if word in name.lower() and "topic" in name.lower()]
    said = (
        f"{topic}: the node did not take the parameter {parameter}:={topic} the harness "
        f"set, as it declares no {parameter}"
    )
    if len(own) == 1:
        return (
            f"{said} (it declares {own[0]}): pass {named('params')} {own[0]}:={topic}, or name the "
            f"parameter {parameter} as the lab does"
        )
    return f"{said}: declare {parameter} and publish on the topic it names"


class ElsewhereWatch:
    """While a link waits for readiness: has the graph shown the node on another scan or
    status topic for ELSEWHERE_GRACE_S? Then waiting longer tells nothing more."""

    def __init__(
        self,
        node: Any,
        options: LinkOptions,
        *,
        reads_scans: Callable[[], bool],
        status_heard: Callable[[], bool],
        watch: bool = True,
    ) -> None:
        self._node, self._options = node, options
        self._reads_scans, self._status_heard = reads_scans, status_heard
        self._watch = watch
        self._began = time.monotonic()
        self._seen_at: float | None = None
        self._next_look = 0.0
        self.gave_up_after: float | None = None  # seconds, once `settled` said so

    def settled(self) -> bool:
        if not self._watch:
            return False
        now = time.monotonic()
        if now >= self._next_look:
            self._next_look = now + LOOK_EVERY_S
            self._look(now)
        if self._seen_at is None or now - self._seen_at < ELSEWHERE_GRACE_S:
            return False
        self.gave_up_after = now - self._began
        return True

    def _look(self, now: float) -> None:
        opts = self._options
        elsewhere = (
            not self._reads_scans()
            and bool(topics_elsewhere(self._node, SCAN_TYPE, opts.scan_topic, publishers=False))
        ) or (
            not self._status_heard()
            and bool(topics_elsewhere(self._node, STRING_TYPE, opts.status_topic, publishers=True))
        )
        if not elsewhere:
            self._seen_at = None
        elif self._seen_at is None:
            self._seen_at = now
