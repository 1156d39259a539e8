"""fossbot-hil: scenario and hardware-in-the-loop tests for the FOSSBot LIDAR lab.

The package is layered: pure logic (``scan``, ``lidar_spec``, ``faults``,
``status``, ``oracle``, ``scenario``) imports neither rclpy nor pybullet;
``sim`` needs pybullet; ``links`` deliver scans to the software under test.
"""

import time as _time

__version__ = "0.1.0"
IMPORTED_AT = _time.monotonic()  # a command's clock starts here (harness.report.wall_clock)
