"""Why a node did not come up or never answered its first scan, in the node's terms (pure).

The link gathers the facts from the graph; the words are here, so they read the
same on every link and are tested without a graph."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from harness.links.base import LinkOptions
from harness.links.topic_advice import ELSEWHERE_GRACE_S

if TYPE_CHECKING:
    from harness.lidar.scan import Scan


def ready_bound_said(ready_timeout: float, gave_up_early_s: float | None) -> str:
    """How long the harness waited for readiness, in words (it stops early once the
    node is seen using other topics: `gave_up_early_s`)."""
    bound = f"{ready_timeout:g} s"
    if gave_up_early_s is None:
        return bound
    return (
        f"{gave_up_early_s:.1f} s (of the {bound} allowed: it uses other topics, "
        f"seen for {ELSEWHERE_GRACE_S:g} s)"
    )


def never_ready(
    node: str,
    options: LinkOptions,
    *,
    reads: bool,
    publishes: bool,
    clock_all_along: bool,
    waited: str,
    graph: str,
) -> str:
    """What the harness waited for (`waited`: for how long, in words), what was missing
    (`reads`: the node subscribed to the scans; `publishes`: it publishes the status) and
    the graph; `clock_all_along`: /clock (time 0) was published while waiting."""
    o = options
    missing = [] if reads else [f"subscribe to {o.scan_topic}"]
    missing += [] if publishes else [f"publish {o.status_topic}"]
    reason = (
        f"it did not {' or '.join(missing)}" if missing else "it was ready only as time ran out"
    )
    if not reads and clock_all_along:
        reason += " (the harness published /clock, time 0, all the while)"
    elif not reads:
        reason += (
            " (the harness publishes /clock only once the node is ready, so a node that waits "
            f"for /clock before it subscribes to {o.scan_topic} never starts)"
        )
    return (
        f"node {node} never became ready within {waited}: the harness waited for it to "
        f"subscribe to {o.scan_topic} and publish {o.status_topic}, but {reason} ({graph})"
    )


def unheard(node: str, wrong_types: Sequence[str], qos_mismatches: Sequence[str]) -> str | None:
    """Why nothing the node publishes can reach the harness, or None: another message
    type on a topic, or best-effort where the harness needs reliable."""
    if wrong_types:
        return (
            f"node {node} uses the wrong message type: {'; '.join(wrong_types)} "
            "(DDS connects only equal types, so nothing crosses)"
        )
    if qos_mismatches:
        return f"node {node} cannot be heard: {'; '.join(qos_mismatches)}"
    return None


def never_answered(node: str, options: LinkOptions, scan: Scan, copies: int) -> str:
    """Why the node's first answer never came: silent on a scan with nothing in range,
    or silent altogether (`copies`: how many times the first scan went)."""
    from harness.judge.oracle import summarise_scan

    o = options
    if not scan.valid_mask().any():
        return (
            f"node {node} is running and subscribed to {o.scan_topic} but published nothing "
            f"on {o.status_topic} for {copies} scans (the first scan, sent {copies} times over "
            f"{o.ready_timeout:g} s), none of which had a valid return ({summarise_scan(scan)}): "
            'a status is expected when nothing is in range too (e.g. "no obstacle")'
        )
    return (
        f"node {node} never answered a scan within {o.ready_timeout:g} s (it subscribes to "
        f"{o.scan_topic} and publishes {o.status_topic}, but no status arrived)"
    )
