"""ROS 2 plumbing shared by the links that watch a ROS graph (imports rclpy)."""
