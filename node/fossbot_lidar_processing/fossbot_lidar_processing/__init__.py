"""
FOSSBot Lab 07 reference solution: LIDAR obstacle status and warning.

colcon installs this folder as ``fossbot_lidar_processing``; fossbot-hil
installs the same folder as ``harness.reference``. So its modules import
each other relatively, and ``scan_logic`` imports no rclpy.
"""
