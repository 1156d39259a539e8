"""The harness's own ROS 2 node: publishes /scan and /clock, hears the answers.

In its own rclpy Context, it waits on a bare rcl wait set over its subscriptions (no
executor: ``spin_once`` rebuilding its wait set was the largest harness cost a scan)
and stamps what it hears with the publisher's DDS source timestamp, so answers are
matched to their scan. It reads the ROS graph too, to say what a node that never
connects offers instead."""

from __future__ import annotations

import os
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import rclpy
from rclpy._rclpy_pybind11 import WaitSet
from rclpy.context import Context
from rclpy.node import NodeNameNonExistentError
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.topic_endpoint_info import TopicEndpointInfo
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool, String

from harness.lidar.scan import Scan, scan_from_message
from harness.ros.announcements import harness_announcements
from harness.ros.cdr import clock_cdr, scan_cdr
from harness.ros.domain import discovery_environment

QOS = QoSProfile(depth=50, reliability=ReliabilityPolicy.RELIABLE)
INBOX_LIMIT = 10_000  # messages kept between two collects: more is a flood, not answers
SCAN_TYPE = "sensor_msgs/msg/LaserScan"
STATUS_TYPE = "std_msgs/msg/String"
WARNING_TYPE = "std_msgs/msg/Bool"
UNKNOWN_NODE_NAME = "_NODE_NAME_UNKNOWN_"  # what discovery says before it knows an endpoint's node
PLUMBING = {"/rosout", "/parameter_events", "/clock"}  # every node has these; not worth naming


@dataclass(frozen=True)
class Heard:
    """One message from the node under test."""

    kind: str  # "status", "warning", or "scan" (a driver's scan, when watching)
    value: str | bool | Scan
    source_ns: int  # when the node published it (DDS source timestamp, system clock)
    arrived: float  # time.perf_counter() when the harness took it


class Observer:
    """Publish scans and collect the node's String and Bool answers."""

    def __init__(
        self,
        domain_id: int,
        *,
        scan_topic: str,
        status_topic: str,
        warning_topic: str,
        network: bool = False,
        publish_scans: bool = True,
    ) -> None:
        # rmw reads the discovery range from the environment at init.
        os.environ.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
        os.environ.update(discovery_environment(network=network))
        self.context = Context()
        self._closed = False
        # Signals are the harness's (rclpy's handlers would shut the context down under us);
        # args=[]: the user's NAME:=VALUE items in sys.argv would remap the harness's node.
        with harness_announcements():  # a node that comes up late is matched at once
            rclpy.init(
                args=[],
                context=self.context,
                domain_id=domain_id,
                signal_handler_options=SignalHandlerOptions.NO,
            )
            # No /rosout (a suite has one of these nodes per domain, whose rosout publishers
            # would clash by name in this process) and no parameter services (a dozen more
            # endpoints for a starting node to discover before it is matched both ways).
            self.node = rclpy.create_node(
                "fossbot_hil",
                context=self.context,
                enable_rosout=False,
                start_parameter_services=False,
            )
        self.scan_topic, self.status_topic = scan_topic, status_topic
        self.warning_topic = warning_topic
        # We publish the scans (ros2), or a board's driver does and we hear them (serial).
        self.scan_pub: Any = None
        self.scan_sub: Any = None
        if publish_scans:
            self.scan_pub = self.node.create_publisher(LaserScan, scan_topic, QOS)
        else:
            hear = self._hear("scan", scan_from_message)
            self.scan_sub = self.node.create_subscription(LaserScan, scan_topic, hear, QOS)
        self.clock_pub = self.node.create_publisher(Clock, "/clock", QOS)
        self.inbox: deque[Heard] = deque(maxlen=INBOX_LIMIT)
        self.heard: Counter[str] = Counter()  # messages of each kind, all told
        self.latest: dict[str, int] = {}  # newest source timestamp of each kind (O(1) checks)
        # The Bool's reader is announced before the String's: endpoint announcements are
        # processed in order, so once a status has reached us the node has matched our
        # Bool reader too, and its first Bool (published after that status) is not lost
        # to a discovery still under way.
        self.warning_sub = self.node.create_subscription(
            Bool, warning_topic, self._hear("warning", lambda m: bool(m.data)), QOS
        )
        self.status_sub = self.node.create_subscription(
            String, status_topic, self._hear("status", lambda m: m.data), QOS
        )
        # What spin and drain wait on and take from: (handle, message type, callback).
        self._subs = [
            (sub.handle, sub.msg_type, sub.callback)
            for sub in (self.scan_sub, self.status_sub, self.warning_sub)
            if sub is not None
        ]
        self._wait_set = WaitSet(len(self._subs), 0, 0, 0, 0, 0, self.context.handle)

    def publish_clock(self, seconds: float) -> None:
        self.clock_pub.publish(clock_cdr(seconds))

    def _hear(self, kind: str, value_of: Callable[[Any], str | bool | Scan]):
        def callback(msg: object, info: dict) -> None:
            source_ns = int(info["source_timestamp"])
            self.heard[kind] += 1
            self.latest[kind] = max(source_ns, self.latest.get(kind, 0))
            self.inbox.append(Heard(kind, value_of(msg), source_ns, time.perf_counter()))

        return callback

    def publish(self, scan: Scan, *, clock: float | None = None) -> int:
        """Publish /clock (`clock`, default the scan's stamp) then the scan;
        return the send time in system-clock ns."""
        assert self.scan_pub is not None, "this observer watches a driver's scans"
        msg = scan_cdr(scan)  # serialized here: rclpy publishes the bytes as they are
        self.clock_pub.publish(clock_cdr(scan.stamp if clock is None else clock))
        sent = time.time_ns()
        self.scan_pub.publish(msg)
        return sent

    def spin(self, timeout: float, limit: int = 100) -> int:
        """Handle what arrived, waiting at most `timeout` seconds for something; at most `limit`
        messages (a flooding node cannot keep it here); returns how many. What arrived already
        is taken without the wait set (a take costs about a microsecond, a wait about a
        hundred, and in lockstep the answer often came while the next scan was simulated)."""
        taken = self.poll(limit)
        if taken or timeout <= 0.0:
            return taken
        wait_set = self._wait_set
        wait_set.clear_entities()
        for handle, _, _ in self._subs:
            wait_set.add_subscription(handle)
        wait_set.wait(int(timeout * 1e9))
        ready = wait_set.get_ready_entities("subscription")
        if not ready:
            return 0
        return self._take([sub for sub in self._subs if sub[0].pointer in ready], limit)

    def poll(self, limit: int = 100) -> int:
        """Handle what has already arrived, without waiting; how many messages it took."""
        return self._take(self._subs, limit)

    @staticmethod
    def _take(subs: list[tuple[Any, Any, Callable[..., None]]], limit: int) -> int:
        taken = 0
        for handle, msg_type, callback in subs:
            while taken < limit:
                got = handle.take_message(msg_type, False)  # (message, message_info) or None
                if got is None:
                    break
                callback(*got)
                taken += 1
        return taken

    def drain(self, limit: int = 100) -> None:
        """Handle everything already queued without waiting (at most `limit` messages)."""
        while limit > 0:
            taken = self.poll(limit)
            if not taken:
                return
            limit -= taken

    def heard_since(self, kind: str, source_ns: int) -> bool:
        """Has a message of `kind` published at or after `source_ns` arrived?"""
        return self.latest.get(kind, 0) >= source_ns

    def statuses_since(self, source_ns: int) -> int:
        """Statuses in the inbox published at or after `source_ns`."""
        return sum(1 for h in self.inbox if h.kind == "status" and h.source_ns >= source_ns)

    def warning_publishers(self) -> int:
        """Publishers of the node's warning topic matched to our subscription."""
        return self.warning_sub.get_publisher_count()

    def ready(self) -> bool:
        """The node reads our scans and publishes its status (matched, not just announced)."""
        if self.scan_pub is not None:
            reads_scans = self.scan_pub.get_subscription_count() > 0
        else:  # the driver publishes scans and someone besides us reads them
            assert self.scan_sub is not None
            reads_scans = (
                self.scan_sub.get_publisher_count() > 0
                and self.node.count_subscribers(self.scan_topic) > 1
            )
        return reads_scans and self.status_sub.get_publisher_count() > 0

    def scan_readers_named(self) -> bool:
        """Has discovery named the node that reads our scans? The node's side may match ours
        after ours matched, and a scan sent before waits for Fast DDS to repair it (0.1-0.4 s
        for a young node); a node is named once its participant announced its entities to us,
        after its side matched: a first scan sent then was never seen repaired late."""
        infos = self.node.get_subscriptions_info_by_topic(self.scan_topic)
        readers = self._others(infos)
        return bool(readers) and all(i.node_name != UNKNOWN_NODE_NAME for i in readers)

    def scan_readers(self) -> int:
        """Readers of the scan topic other than this observer."""
        if self.scan_pub is not None:
            return self.scan_pub.get_subscription_count()
        return self.node.count_subscribers(self.scan_topic) - 1

    def strangers(self) -> str:
        """Who else shares this run's domain: more than one participant publishing the scans or
        the status ('' when no one does), e.g. a node left by an earlier run, which makes the
        node seem to answer twice. Endpoints count by participant (their gid's 12-byte GUID
        prefix), so one node counts once."""
        found = []
        for topic in (self.scan_topic, self.status_topic):
            infos = self.node.get_publishers_info_by_topic(topic)
            participants = {bytes(i.endpoint_gid[:12]) for i in infos}
            if len(participants) > 1:
                named = {_full_name(i) for i in infos if i.node_name != UNKNOWN_NODE_NAME}
                names = ", ".join(sorted(named)) or "discovery has not named their nodes yet"
                found.append(f"{len(participants)} ROS participants publish {topic} ({names})")
        return "; ".join(found)

    # -- the graph: what the node under test offers ---------------------------
    def _others(self, infos: list[TopicEndpointInfo]) -> list[TopicEndpointInfo]:
        """Endpoints that are not this observer's."""
        me = (self.node.get_name(), self.node.get_namespace())
        return [i for i in infos if (i.node_name, i.node_namespace) != me]

    def _wrong_type(
        self, topic: str, want: str, *, publishers: bool, named_only: bool
    ) -> str | None:
        """'NODE publishes TOPIC as TYPE' when others use `topic` only with other types."""
        infos = self._others(
            self.node.get_publishers_info_by_topic(topic)
            if publishers
            else self.node.get_subscriptions_info_by_topic(topic)
        )
        if not infos or any(i.topic_type == want for i in infos):
            return None
        if named_only and any(i.node_name == UNKNOWN_NODE_NAME for i in infos):
            return None  # discovery has the endpoint but not its node yet
        does, expects = ("publishes", "expects") if publishers else ("subscribes to", "publishes")
        who = sorted({f"{_full_name(i)} {does} {topic} as {i.topic_type}" for i in infos})
        return f"{', '.join(who)}, but the harness {expects} {want}"

    def wrong_types(self, *, named_only: bool = False) -> list[str]:
        """Topics the node uses with another message type than the harness: DDS never connects
        them, so say it rather than "never ready" or "no answer". `named_only`: a topic whose
        endpoints discovery has not tied to a node yet is left for later."""
        checks = [(self.status_topic, STATUS_TYPE, True), (self.warning_topic, WARNING_TYPE, True)]
        if self.scan_pub is not None:
            checks.append((self.scan_topic, SCAN_TYPE, False))
        found = (self._wrong_type(t, w, publishers=p, named_only=named_only) for t, w, p in checks)
        return [c for c in found if c is not None]

    def qos_mismatches(self) -> list[str]:
        """Publishers of the right type that our reliable subscriptions can never match."""
        found = []
        for sub, topic, want in (
            (self.status_sub, self.status_topic, STATUS_TYPE),
            (self.warning_sub, self.warning_topic, WARNING_TYPE),
        ):
            if sub.get_publisher_count() > 0:
                continue
            for info in self._others(self.node.get_publishers_info_by_topic(topic)):
                if info.topic_type == want and (
                    info.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
                ):
                    found.append(
                        f"{_full_name(info)} publishes {topic} best-effort, but the harness "
                        "subscribes reliable, which DDS never matches: publish reliable "
                        "(the default QoS)"
                    )
                    break
        return found

    def node_topics(self) -> str:
        """What each other node in the domain publishes and subscribes to, in one line."""
        described = []
        me = (self.node.get_name(), self.node.get_namespace())
        for name, namespace in self.node.get_node_names_and_namespaces():
            if (name, namespace) == me:
                continue
            try:
                pubs = self.node.get_publisher_names_and_types_by_node(name, namespace)
                subs = self.node.get_subscriber_names_and_types_by_node(name, namespace)
            except NodeNameNonExistentError:  # it left the graph meanwhile
                continue
            full = f"{namespace.rstrip('/')}/{name}"
            described.append(
                f"{full} publishes {_topic_list(pubs)} and subscribes to {_topic_list(subs)}"
            )
        return "; ".join(described) or "no other node in this ROS domain"

    def graph_summary(self) -> str:
        """What the node under test offers, for 'never became ready' explanations."""
        counts = (
            f"subscribers on {self.scan_topic}: {self.scan_readers()}, "
            f"publishers on {self.status_topic}: {self.status_sub.get_publisher_count()}"
        )
        return "; ".join([counts, *self.qos_mismatches(), self.node_topics()])

    @property
    def usable(self) -> bool:
        """Not closed, and its context not shut down."""
        return not self._closed and self.context.ok()

    def close(self) -> None:
        """Tear down wait set, node and context, in that order; safe twice. The context too: until
        then its participant lives on, seen by a later run in the domain."""
        if self._closed:
            return
        self._closed = True
        if self.context.ok():
            self._wait_set.destroy_when_not_in_use()
            self.node.destroy_node()
            self.context.try_shutdown()
            self.context.destroy()


def _full_name(info: TopicEndpointInfo) -> str:
    """The endpoint's node, e.g. /fossbot_lidar_node (DDS may know the endpoint first)."""
    if info.node_name == UNKNOWN_NODE_NAME:
        return "the node"
    return f"{info.node_namespace.rstrip('/')}/{info.node_name}"


def _topic_list(names_and_types: list[tuple[str, list[str]]]) -> str:
    """'/a (std_msgs/msg/String), /b (...)' without the topics every node has."""
    shown = [
        f"{t} ({', '.join(types)})" for t, types in sorted(names_and_types) if t not in PLUMBING
    ]
    return ", ".join(shown) or "nothing"
