"""
The Lab 07 listing's launch file, with its defect (a test fixture).

It is the bundled node's launch/lidar_node_launch.py as the lab wrote it:
the status topic goes to the node as `lidar_info_topic`, a parameter the
node never declares (it declares `lidar_status_topic`), so the status
topic silently stays at its default.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue


def generate_launch_description():
    """Declare the arguments and the node."""
    arguments = [
        DeclareLaunchArgument('lidar_topic', default_value='/scan'),
        DeclareLaunchArgument('lidar_info_topic', default_value='/lidar_status'),
        DeclareLaunchArgument('warning_topic', default_value='/obstacle_warning'),
        DeclareLaunchArgument('threshold', default_value='0.5'),
        DeclareLaunchArgument('use_sim_time', default_value='false'),
    ]
    node = Node(
        package='fossbot_lidar_processing',
        executable='fossbot_lidar_node',
        name='fossbot_lidar_node',
        output='screen',
        parameters=[
            {
                'lidar_topic': LaunchConfiguration('lidar_topic'),
                'lidar_info_topic': LaunchConfiguration('lidar_info_topic'),
                'warning_topic': LaunchConfiguration('warning_topic'),
                'threshold': ParameterValue(LaunchConfiguration('threshold'), value_type=float),
                'use_sim_time': ParameterValue(
                    LaunchConfiguration('use_sim_time'), value_type=bool
                ),
            }
        ],
    )
    return LaunchDescription([*arguments, node])
