"""ROS 2 plumbing shared by the links that watch a ROS graph.

- ``observer``: the harness's own rclpy node (publishes /scan and /clock,
  collects the node's answers); ``messages``: Scan <-> LaserScan;
  ``parameters``: which parameters a running node declares (asked over
  ListParameters). These import rclpy;
- ``domain``: a ROS_DOMAIN_ID reserved per run, so parallel runs never see
  each other; ``names``: topic and parameter names as ROS checks them;
  ``cdr``: the scan and clock as the bytes rmw publishes. These are pure:
  the command line uses the first two without rclpy.
"""
