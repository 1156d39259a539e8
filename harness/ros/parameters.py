"""Which parameters a running node declares, asked over rcl_interfaces' ListParameters.

A node sees only the launch file's overrides it declares; the question goes from a
short-lived node in the harness's context, bounded, and comes back as plain data."""

from __future__ import annotations

import time

import rclpy
from rcl_interfaces.srv import ListParameters
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

__all__ = ["ASK_TIMEOUT_S", "declared_parameters", "node_on"]

ASK_TIMEOUT_S = 3.0  # for the service to be seen and to answer, together
POLL_S = 0.05


def node_on(node: Node, topics: list[tuple[str, bool]]) -> str | None:
    """The full name of the first other node that publishes (True) or subscribes to
    (False) one of `topics`, in order: the node under test, as the graph knows it."""
    me = (node.get_name(), node.get_namespace())
    for topic, publishes in topics:
        get = (
            node.get_publishers_info_by_topic if publishes else node.get_subscriptions_info_by_topic
        )
        for info in get(topic):
            if (info.node_name, info.node_namespace) != me:
                return f"{info.node_namespace.rstrip('/')}/{info.node_name}"
    return None


def declared_parameters(
    context: Context, full_name: str, timeout: float = ASK_TIMEOUT_S
) -> list[str] | str:
    """The names `full_name` (``/ns/name``) declares, or why it gave none in `timeout`."""
    service = f"{full_name}/list_parameters"
    node = rclpy.create_node(
        "fossbot_hil_parameters",
        context=context,
        enable_rosout=False,
        start_parameter_services=False,
    )
    executor = SingleThreadedExecutor(context=context)
    try:
        executor.add_node(node)
        client = node.create_client(ListParameters, service)
        deadline = time.monotonic() + timeout
        while not client.service_is_ready():
            if time.monotonic() >= deadline:
                return f"{full_name} offers no {service} service (waited {timeout:g} s)"
            executor.spin_once(timeout_sec=POLL_S)
        future = client.call_async(ListParameters.Request())  # depth 0: all of them
        while not future.done():
            left = deadline - time.monotonic()
            if left <= 0:
                future.cancel()
                return f"{service} gave no answer in {timeout:g} s"
            executor.spin_once(timeout_sec=min(POLL_S, left))
        return list(future.result().result.names)
    finally:
        executor.remove_node(node)
        executor.shutdown(timeout_sec=1.0)
        node.destroy_node()
