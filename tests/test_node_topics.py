"""A scenario's node_topics: checked as ROS topic names, and set through the node's topic
parameters on a link that publishes the scans itself, unless the run named its own."""

from __future__ import annotations

from dataclasses import replace

import pytest

from harness.errors import ConfigError
from harness.links.base import LinkOptions
from harness.runner.plan import node_topic_options, plan_run
from harness.runner.settings import RunSettings
from harness.scenario.files import resolve_scenario


def with_topics(**topics: str) -> object:
    base = resolve_scenario("approach_wall")
    data = base.model_dump(mode="json") | {"node_topics": topics}
    return type(base).model_validate(data)


def test_the_lab_parameters_get_the_scenario_topics() -> None:
    scenario = resolve_scenario("obstacle_at_side")
    options = node_topic_options(scenario, LinkOptions())
    assert (options.scan_topic, options.status_topic, options.warning_topic) == (
        "/fossbot2/scan",
        "/fossbot2/lidar_status",
        "/fossbot2/obstacle_warning",
    )
    assert options.params == (
        "lidar_topic:=/fossbot2/scan",
        "lidar_status_topic:=/fossbot2/lidar_status",
        "warning_topic:=/fossbot2/obstacle_warning",
    )


def test_only_the_links_that_publish_the_scans_set_them() -> None:
    scenario = resolve_scenario("obstacle_at_side")
    ros2 = plan_run(scenario, "ros2", LinkOptions(), RunSettings()).options
    board = plan_run(scenario, "rplidar", LinkOptions(), RunSettings()).options
    assert ros2.scan_topic == "/fossbot2/scan" and board.scan_topic == "/scan"
    assert board.params == ()


def test_a_run_with_its_own_topics_or_topic_parameters_keeps_them() -> None:
    scenario = resolve_scenario("obstacle_at_side")
    own = replace(LinkOptions(), scan_topic="/robot/scan", params=("lidar_topic:=/robot/scan",))
    assert node_topic_options(scenario, own) == own
    param = replace(LinkOptions(), params=("warning_topic:=/warn",))
    assert node_topic_options(scenario, param) == param
    other = replace(LinkOptions(), params=("delay_s:=0.1",))
    assert node_topic_options(scenario, other).params[0] == "delay_s:=0.1"


def test_only_the_topics_named_change() -> None:
    options = node_topic_options(with_topics(status="lidar_info"), LinkOptions())
    assert options.status_topic == "/lidar_info"  # relative: from the root namespace
    assert options.scan_topic == "/scan" and options.params == ("lidar_status_topic:=/lidar_info",)


@pytest.mark.parametrize(
    "topics, says",
    [
        ({"scan": "/bad topic"}, "node_topics.scan"),
        ({"scan": "/a", "status": "/a"}, "different topics"),
        ({"scan": "~/private"}, "node_topics.scan"),
    ],
)
def test_bad_topics_are_refused(topics: dict[str, str], says: str) -> None:
    with pytest.raises((ConfigError, ValueError)) as caught:
        with_topics(**topics)
    assert says in str(caught.value) or "node_topics" in str(caught.value), caught.value
