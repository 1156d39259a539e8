"""
Build script for the ament_python package, as `ros2 pkg create` lays it out.

The lab's listing imported `from glob import glob` and then called
`glob.glob(...)`, an AttributeError at build time; here `glob` is the
function itself.
"""

from glob import glob
import os

from setuptools import find_packages, setup

package_name = 'fossbot_lidar_processing'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        (os.path.join('share', package_name, 'launch'), glob('launch/*_launch.py')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='fossbot-hil maintainers',
    maintainer_email='fossbot-hil@example.invalid',
    description='FOSSBot Lab 07 LIDAR obstacle status and warning node (reference solution)',
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'fossbot_lidar_node = fossbot_lidar_processing.lidar_node:main',
        ],
    },
)
