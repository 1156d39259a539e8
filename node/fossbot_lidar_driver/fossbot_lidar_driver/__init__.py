"""
Board-side LIDAR drivers of a virtual FOSSBot: serial LIDAR in, LaserScan out.

``rplidar_node`` reads a Slamtec RPLIDAR A1 (the FOSSBot v2's LIDAR) with the
PyPI ``rplidar`` package; ``ldlidar_node`` reads an LDROBOT LD06/LD19 with
its own small parser. The pure parts (``binning``, ``revolutions``,
``ld_protocol``) import no rclpy, so they test in milliseconds; modules
import each other relatively, so the folder can be shipped under another
package name too.
"""
