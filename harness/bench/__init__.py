"""`fossbot-hil bench`: the stages that measure the harness, one module each."""

from harness.links.kinds import INPROCESS, ROS2

# The stages, in the order they run (cheapest first); here so that naming
# them (`fossbot-hil bench --help`) imports none of them. The two link stages
# are named after the link they measure.
STAGES = ("raycast", "synthesis", INPROCESS, ROS2, "serial", "pacing", "suite", "grade", "hil")
