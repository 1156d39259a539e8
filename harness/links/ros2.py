"""The ros2 link: a real node in its own process, over a real DDS graph.

It composes the node's graph (``node_graph``) and the exchange (``node_exchange``) with
the simplest delivery: each scan published on the scan topic. A hostile node gets a
verdict, not a hang (docs/hostile_nodes.md)."""

from __future__ import annotations

import contextlib
import time
from typing import TYPE_CHECKING

from harness.errors import ConfigError
from harness.links.base import Link, LinkOptions, Part, register
from harness.links.bounds import CATCH_UP_S, NAMED_WAIT_S
from harness.links.node_exchange import NodeExchange, ScanDelivery
from harness.links.node_graph import NodeGraph
from harness.links.node_notes import WiringNotes
from harness.links.node_start import launch_check, node_command
from harness.nodes.process import prepare_start
from harness.ros.domain import reserve_domain

if TYPE_CHECKING:  # numpy and rclpy are imported when the first link starts, after its node
    from harness.launch_files.run_check import LaunchCheck  # read for --package, --launch
    from harness.lidar.scan import Scan

__all__ = ["CATCH_UP_S", "NAMED_WAIT_S", "Ros2Link", "TopicDelivery"]


class TopicDelivery(ScanDelivery):
    """Scans published on the scan topic, the status answering one is the first after it."""

    copies_queue = True

    def __init__(self, exchange: NodeExchange) -> None:
        self.exchange = exchange

    def deliver(self, scan: Scan, tick: int, *, clock: float | None = None) -> int:
        assert self.exchange.graph.observer is not None
        return self.exchange.graph.observer.publish(scan, clock=clock)

    def answered(self) -> bool:
        assert self.exchange.graph.observer is not None
        return self.exchange.graph.observer.heard_since("status", self.exchange.sent_ns)


@register("ros2")
class Ros2Link(Link):
    """Drive a ROS 2 node process through its scan topic; watch status and warning."""

    sets_node_topics = True
    starts_ahead = True  # each link has its own domain, so several can be up at once

    def __init__(self, options: LinkOptions, session: LaunchCheck | None = None) -> None:
        super().__init__(options)
        self.command = node_command(options)  # resolve now: bad input exits 2 early
        self.graph = NodeGraph(options, self.command, WiringNotes(options, session))
        self.node_exchange = NodeExchange(self.graph, TopicDelivery)
        self.startup_s = 0.0

    # The graph's and the exchange's, as the runner and the tests read them (`exchange`,
    # send then collect, is the base class's: the part is `node_exchange`).
    observer = Part("graph")
    process = Part("graph")
    domain = Part("graph")
    node_start = Part("graph")
    node_gone = Part("graph")
    stop = Part("graph")
    close = Part("graph")
    stop_note = Part("graph")
    send_first = Part("node_exchange")
    warm_up = Part("node_exchange")
    send = Part("node_exchange")
    hold = Part("node_exchange")
    collect = Part("node_exchange")
    settle = Part("node_exchange")

    # -- life cycle -------------------------------------------------------
    @classmethod
    def run_session(
        cls, options: LinkOptions
    ) -> contextlib.AbstractContextManager[LaunchCheck | None]:
        """The package's launch files, read once for the run (harness.launch_files)."""
        return contextlib.nullcontext(launch_check(options))

    @classmethod
    def prepare(cls, options: LinkOptions) -> None:
        """Start the fork server of the node, if it has one (its imports take a while)."""
        with contextlib.suppress(ConfigError):  # a bad node is reported where it is used
            prepare_start(node_command(options))

    def start(self) -> None:
        """Start the node in a domain of its own without waiting (a suite starts the next
        scenarios' links while one runs); `open` waits for readiness."""
        self.graph.start(reserve_domain)

    def open(self) -> None:
        """Start (unless started ahead) and wait, bounded, until the node is ready."""
        started = time.perf_counter()
        self.start()
        self.graph.open()
        self.startup_s = time.perf_counter() - started

    def diagnostics(self) -> str:
        """The node's last output and what the graph showed; then ask the node to stop
        (the runner asks once, when the run is over)."""
        if self.graph.process is None:
            return ""
        text = self.graph.diagnostics(warmed_up=self.node_exchange.warmed_up)
        self.stop()
        return text

    def notices(self) -> list[str]:
        return self.graph.notices(warmed_up=self.node_exchange.warmed_up)
