"""
Build script for the ament_python package, as `ros2 pkg create` lays it out.

`rplidar` (PyPI, SkoltechRobotics, 0.9.2) has no rosdep key, so it is
named here, in install_requires, and must be pip-installed on the robot.
"""

from setuptools import find_packages, setup

package_name = 'fossbot_lidar_driver'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
    ],
    install_requires=['setuptools', 'numpy', 'pyserial', 'rplidar'],
    zip_safe=True,
    maintainer='fossbot-hil maintainers',
    maintainer_email='fossbot-hil@example.invalid',
    description='Serial LIDAR (RPLIDAR A1, LD06/LD19) to LaserScan for a virtual FOSSBot',
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'rplidar_node = fossbot_lidar_driver.rplidar_node:main',
            'ldlidar_node = fossbot_lidar_driver.ldlidar_node:main',
        ],
    },
)
