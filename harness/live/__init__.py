"""The lab's simulator: the world in real time, driven live, watched, judged while driving.

``fossbot-hil sim`` runs a scenario's world in wall-clock time: the robot
follows ``/cmd_vel`` (or the keyboard, ``teleop``) on its wheels, the LIDAR
publishes ``/scan``, with ``/odom``, ``/clock`` and ``/tf`` as the lab's
Gazebo bridge does; ``foxglove_view`` serves it all to the Foxglove app;
a student's node started beside it is judged on every scan as it answers.
"""
