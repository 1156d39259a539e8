"""`fossbot-hil bench`: the stages that measure the harness, one module each."""

# The stages, in the order they run (cheapest first); here so that naming
# them (`fossbot-hil bench --help`) imports none of them.
STAGES = ("raycast", "synthesis", "inprocess", "ros2", "serial", "pacing", "suite", "grade")
