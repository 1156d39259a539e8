"""What a run learned about the node under test, for its report: output, wiring, launch files.

Read from the graph before the node stops: the node-side half of a link, with no
lockstep state."""

from __future__ import annotations

from typing import TYPE_CHECKING

from harness.links.base import LinkOptions
from harness.links.topic_advice import BOOL_TYPE, topics_elsewhere, untaken_topic_parameter
from harness.option_names import named

if TYPE_CHECKING:
    from harness.launch_files.run_check import Asked, LaunchCheck
    from harness.nodes.process import NodeProcess
    from harness.ros.observer import Observer

LOUD_BYTES = 1 << 20  # a node that wrote more than this is told how much, in the diagnostics


def output_notes(process: NodeProcess) -> list[str]:
    """The node's last lines on stderr, then stdout, and how much a loud one wrote."""
    parts = []
    for which in ("stderr", "stdout"):
        tail = process.tail(which)
        written = process.output_bytes(which)
        if written > LOUD_BYTES:
            parts.append(f"node {which}: {written / 1e6:.0f} MB written (last lines below)")
        if tail:
            parts.append(f"node {which} (last lines):\n{tail}")
    return parts


def ask_parameters(observer: Observer, options: LinkOptions) -> Asked:
    """(the node under test's name, the parameters it declares), or why not known."""
    from harness.ros.parameters import declared_parameters, node_on

    topics = [(options.status_topic, True), (options.scan_topic, False)]
    node = node_on(observer.node, topics)
    if node is None:
        return f"no node publishes {options.status_topic} or reads {options.scan_topic}"
    declared = declared_parameters(observer.context, node)
    return declared if isinstance(declared, str) else (node.lstrip("/"), declared)


class WiringNotes:
    """How the node is wired where it is not as the lab's, noted once a run."""

    def __init__(self, options: LinkOptions, launch_check: LaunchCheck | None) -> None:
        self.options = options
        self.launch_check = launch_check  # the run's launch files, checked once a run
        self._topic_notes: list[str] | None = None  # taken once

    def notices(self, observer: Observer | None, *, warmed_up: bool, running: bool) -> list[str]:
        """The topic notes, then what the launch files get wrong (`warmed_up`: the node
        answered; `running`: it has not exited, so it can be asked its parameters)."""
        return self._topics(observer, warmed_up) + self._launch(observer, warmed_up and running)

    def graph_notes(
        self, observer: Observer | None, *, warmed_up: bool, running: bool
    ) -> list[str]:
        """Topic trouble in the graph at the end (a publisher made after it was ready)."""
        if observer is None or not observer.usable:
            return []
        notes = [f"wrong message type: {w}" for w in observer.wrong_types()]
        return notes or self.notices(observer, warmed_up=warmed_up, running=running)

    def _launch(self, observer: Observer | None, up: bool) -> list[str]:
        """The run's launch-file notes; the first scenario whose node is up at its end
        asks the node which parameters it declares."""
        check = self.launch_check
        if check is None:
            return []
        if observer is None or not observer.usable or not up:
            return check.notes(None)
        return check.notes(lambda: ask_parameters(observer, self.options))

    def _topics(self, observer: Observer | None, warmed_up: bool) -> list[str]:
        """On which topic the node publishes its Bool instead of the warning topic, and the option
        that names it (else the graph); taken once, before the diagnostics stop the node."""
        if self._topic_notes is not None:
            return list(self._topic_notes)
        self._topic_notes = notes = []
        obs, opts = observer, self.options
        if obs is None or not obs.usable or not warmed_up or obs.wrong_types():
            return []
        if obs.heard["warning"] or obs.warning_publishers():
            return []
        elsewhere = topics_elsewhere(obs.node, BOOL_TYPE, opts.warning_topic, publishers=True)
        untaken = untaken_topic_parameter(
            opts, opts.topic_params[2], opts.warning_topic, lambda: ask_parameters(obs, opts)
        )
        if len(elsewhere) == 1 and untaken is not None:
            notes.append(f"the node publishes a Bool on {elsewhere[0]}, not {untaken}")
        elif len(elsewhere) == 1:
            notes.append(
                f"the node publishes a Bool on {elsewhere[0]}, not {opts.warning_topic}: pass "
                f"{named('warning_topic')} {elsewhere[0]} if that is the lab's name"
            )
        elif elsewhere:
            notes.append(
                f"the node publishes Bools on {', '.join(elsewhere)}, not {opts.warning_topic}: "
                f"pass {named('warning_topic')} with the lab's name"
            )
        else:
            notes.append(
                f"no Bool came on {opts.warning_topic} all run; the graph: {obs.node_topics()}"
            )
        return list(notes)
