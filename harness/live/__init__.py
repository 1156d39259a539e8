"""The lab's simulator: the world in real time, driven live, watched, judged while driving.

``fossbot-hil sim``: the robot follows ``/cmd_vel`` on its wheels and the
topics are the lab's Gazebo bridge's, so a student's node runs as in the lab.
"""
