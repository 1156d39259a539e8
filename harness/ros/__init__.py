"""ROS 2 plumbing shared by the links that watch a ROS graph.

``observer``, ``messages`` and ``parameters`` import rclpy; ``domain``, ``names`` and
``cdr`` are pure (the command line uses the first two without rclpy)."""
