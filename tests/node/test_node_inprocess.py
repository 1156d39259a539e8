"""The node class inside the test process: parameters, publish order, scan QoS."""

from __future__ import annotations

import pytest

pytestmark = [pytest.mark.ros, pytest.mark.timeout(30)]


@pytest.fixture
def lidar_node_module():
    """harness.reference.lidar_node (it imports rclpy: the module is marked `ros`)."""
    from harness.reference import lidar_node

    return lidar_node


def start_in_process(ros_context, module, **overrides):
    """A LidarProcessingNode in the test's Context, with parameter overrides."""
    from rclpy.parameter import Parameter

    return ros_context.add(
        module.LidarProcessingNode(
            context=ros_context.context,
            parameter_overrides=[Parameter(name, value=v) for name, v in overrides.items()],
        )
    )


def test_defaults(ros_context, lidar_node_module) -> None:
    """The parameters default to the lab's topics and a 0.5 m threshold."""
    node = start_in_process(ros_context, lidar_node_module)
    assert node.get_name() == "fossbot_lidar_node"
    values = {
        name: node.get_parameter(name).value
        for name in ("lidar_topic", "lidar_status_topic", "warning_topic", "threshold", "scan_qos")
    }
    assert values == {
        "lidar_topic": "/scan",
        "lidar_status_topic": "/lidar_status",
        "warning_topic": "/obstacle_warning",
        "threshold": 0.5,
        "scan_qos": "reliable",
    }
    assert node.threshold == 0.5


@pytest.mark.parametrize("value", [0.0, -1.0, float("nan"), "close"])
def test_bad_threshold_raises_config_error(ros_context, lidar_node_module, value) -> None:
    """Construction refuses an unusable threshold with ConfigError (main maps it to exit 2)."""
    with pytest.raises(lidar_node_module.ConfigError, match="threshold"):
        start_in_process(ros_context, lidar_node_module, threshold=value)


def test_threshold_can_change_at_run_time(ros_context, lidar_node_module) -> None:
    """`ros2 param set threshold` takes effect; an invalid value is refused and changes nothing."""
    from rclpy.parameter import Parameter

    node = start_in_process(ros_context, lidar_node_module, threshold=0.4)
    (ok,) = node.set_parameters([Parameter("threshold", value=0.8)])
    assert ok.successful and node.threshold == 0.8
    (bad,) = node.set_parameters([Parameter("threshold", value=-0.1)])
    assert not bad.successful and "> 0" in bad.reason
    assert node.threshold == 0.8


def test_topics_are_read_only(ros_context, lidar_node_module) -> None:
    """Topic parameters cannot change at run time (the node would not re-subscribe)."""
    from rclpy.parameter import Parameter

    node = start_in_process(ros_context, lidar_node_module)
    (result,) = node.set_parameters([Parameter("lidar_topic", value="/other")])
    assert not result.successful


def test_bool_is_published_before_string(
    ros_context, ros_graph, lidar_node_module, make_scan_fn
) -> None:
    """The warning goes out before the status, so the String can mark "answer complete"."""
    node = start_in_process(ros_context, lidar_node_module, threshold=0.4)
    order: list[str] = []
    for label, publisher in (("bool", node._warning_pub), ("string", node._status_pub)):
        real = publisher.publish

        def spy(msg, real=real, label=label):
            order.append(label)
            real(msg)

        publisher.publish = spy
    graph = ros_graph()
    graph.handshake()
    order.clear()
    answer = graph.ask(make_scan_fn([0.3]))
    assert answer.warning is True
    assert order == ["bool", "string"]


def test_sensor_data_qos_hears_a_best_effort_driver(
    ros_context, ros_graph, lidar_node_module, make_scan_fn
) -> None:
    """With scan_qos:=sensor_data the node answers a driver publishing best effort."""
    from rclpy.qos import qos_profile_sensor_data

    start_in_process(ros_context, lidar_node_module, scan_qos="sensor_data")
    graph = ros_graph(scan_qos=qos_profile_sensor_data)
    graph.handshake()
    answer = graph.ask(make_scan_fn([2.0]))
    assert (answer.status, answer.warning) == ("Min distance: 2.000 m, angle: -3.142 rad", False)
