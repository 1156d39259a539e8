"""The topics the lab's Gazebo bridge speaks, on the harness's own ROS 2 node.

Beside the observer's topics: ``/cmd_vel`` in, ``/odom`` out, and ``/tf`` and
``/tf_static`` where tf2_msgs is importable (the ROS 2 wheels on the package
index have none: then ``tf_missing`` says so and ``/odom`` carries the pose).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from harness.ros.messages import stamp
from harness.ros.observer import QOS, Observer
from harness.sim.motion import Pose

CMD_VEL = "/cmd_vel"
ODOM = "/odom"
ODOM_FRAME, BASE_FRAME = "odom", "base_footprint"
CMD_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)  # as teleop publishes
STATIC_QOS = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
COMMANDS_PER_POLL = 100  # a flood of commands cannot hold the loop


@dataclass(frozen=True)
class Command:
    """One /cmd_vel message: forward m/s and yaw rate rad/s (the rest of a Twist is ignored)."""

    linear: float
    angular: float


class LiveBridge:
    """/cmd_vel in; /odom, /tf and /tf_static out, on the observer's node."""

    def __init__(self, observer: Observer, lidar_frame: str, lidar_offset: Pose) -> None:
        node = self._node = observer.node
        self._sub = node.create_subscription(Twist, CMD_VEL, lambda msg: None, CMD_QOS)
        self._cmd: Any = None  # a publisher of our own, for the keyboard
        self._odom = node.create_publisher(Odometry, ODOM, QOS)
        self.tf_missing: str | None = None
        self._tf: Any = None
        try:
            from tf2_msgs.msg import TFMessage
        except ImportError:
            self.tf_missing = "no /tf: tf2_msgs is not installed here (/odom carries the pose)"
        else:
            self._tf_type = TFMessage
            self._tf = node.create_publisher(TFMessage, "/tf", QOS)
            static = node.create_publisher(TFMessage, "/tf_static", STATIC_QOS)
            static.publish(
                TFMessage(transforms=[_transform(0.0, BASE_FRAME, lidar_frame, lidar_offset)])
            )

    def commands(self) -> list[Command]:
        """The /cmd_vel messages that arrived since the last call, oldest first."""
        heard = []
        for _ in range(COMMANDS_PER_POLL):
            got = self._sub.handle.take_message(Twist, False)
            if got is None:
                break
            twist = got[0]
            heard.append(Command(float(twist.linear.x), float(twist.angular.z)))
        return heard

    def publish_command(self, linear: float, angular: float) -> None:
        """Publish a /cmd_vel (the keyboard's): every /cmd_vel subscriber hears it, this one too."""
        if self._cmd is None:
            self._cmd = self._node.create_publisher(Twist, CMD_VEL, CMD_QOS)
        twist = Twist()
        twist.linear.x, twist.angular.z = linear, angular
        self._cmd.publish(twist)

    def publish_odometry(self, t: float, pose: Pose, velocity: tuple[float, float]) -> None:
        """/odom (and /tf where it exists) for the robot's pose at simulation time `t`."""
        msg = Odometry()
        msg.header.stamp = stamp(t)
        msg.header.frame_id = ODOM_FRAME
        msg.child_frame_id = BASE_FRAME
        msg.pose.pose.position.x, msg.pose.pose.position.y = pose.x, pose.y
        qz, qw = math.sin(pose.yaw / 2.0), math.cos(pose.yaw / 2.0)
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = qz, qw
        msg.twist.twist.linear.x, msg.twist.twist.angular.z = velocity
        self._odom.publish(msg)
        if self._tf is not None:
            self._tf.publish(
                self._tf_type(transforms=[_transform(t, ODOM_FRAME, BASE_FRAME, pose)])
            )


def _transform(t: float, parent: str, child: str, pose: Pose) -> Any:
    from geometry_msgs.msg import TransformStamped

    msg = TransformStamped()
    msg.header.stamp = stamp(t)
    msg.header.frame_id = parent
    msg.child_frame_id = child
    msg.transform.translation.x, msg.transform.translation.y = pose.x, pose.y
    msg.transform.rotation.z = math.sin(pose.yaw / 2.0)
    msg.transform.rotation.w = math.cos(pose.yaw / 2.0)
    return msg
