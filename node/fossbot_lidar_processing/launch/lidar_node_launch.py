"""
Launch the Lab 07 LIDAR node, optionally with the FOSSBot Gazebo world.

    ros2 launch fossbot_lidar_processing lidar_node_launch.py threshold:=0.4
    ros2 launch fossbot_lidar_processing lidar_node_launch.py start_sim:=true

lidar_topic, lidar_status_topic, warning_topic, threshold and use_sim_time
reach the node as the parameters of the same names. The
lab's listing passed `lidar_info_topic`, a parameter the node never
declares, so the status topic silently stayed at its default; here the
argument and the parameter are both `lidar_status_topic`.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    """Declare the arguments, the optional simulator and the node."""
    arguments = [
        DeclareLaunchArgument(
            'lidar_topic', default_value='/scan', description='LaserScan topic to read'
        ),
        DeclareLaunchArgument(
            'lidar_status_topic',
            default_value='/lidar_status',
            description='std_msgs/String status topic',
        ),
        DeclareLaunchArgument(
            'warning_topic',
            default_value='/obstacle_warning',
            description='std_msgs/Bool warning topic',
        ),
        DeclareLaunchArgument(
            'threshold', default_value='0.5', description='warning distance in metres (> 0)'
        ),
        DeclareLaunchArgument(
            'use_sim_time',
            default_value='false',
            description='use /clock (true with a simulator or the harness)',
        ),
        DeclareLaunchArgument(
            'start_sim', default_value='false', description='also launch the FOSSBot Gazebo world'
        ),
        DeclareLaunchArgument(
            'world',
            default_value='single_wall.sdf',
            description='world for fossbot_educational_description single.launch.py',
        ),
    ]
    simulator = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(
            PathJoinSubstitution(
                [FindPackageShare('fossbot_educational_description'), 'launch', 'single.launch.py']
            )
        ),
        launch_arguments={'world': LaunchConfiguration('world')}.items(),
        condition=IfCondition(LaunchConfiguration('start_sim')),
    )
    node = Node(
        package='fossbot_lidar_processing',
        executable='fossbot_lidar_node',
        name='fossbot_lidar_node',
        output='screen',
        parameters=[
            {
                'lidar_topic': LaunchConfiguration('lidar_topic'),
                'lidar_status_topic': LaunchConfiguration('lidar_status_topic'),
                'warning_topic': LaunchConfiguration('warning_topic'),
                # Typed explicitly: `threshold:=1` must still reach the node
                # as a number and `use_sim_time:=true` as a bool, not text.
                'threshold': ParameterValue(LaunchConfiguration('threshold'), value_type=float),
                'use_sim_time': ParameterValue(
                    LaunchConfiguration('use_sim_time'), value_type=bool
                ),
            }
        ],
    )
    return LaunchDescription([*arguments, simulator, node])
