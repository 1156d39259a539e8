"""Stage 'serial': lockstep through the virtual board, the rplidar link.

The emulated A1M8 on a pty, the bundled board driver and the reference node,
each in its own process, as ``fossbot-hil run --link rplidar`` runs them.
"""

from __future__ import annotations

from harness.bench.ros2_lockstep import measure_link
from harness.bench.stage import StageResult
from harness.bench.workload import Workload
from harness.links.kinds import default_serial_link


def measure_serial(workload: Workload) -> StageResult:
    """The rplidar link: a virtual board (emulated A1M8 on a pty, its driver, the node)."""
    result = measure_link(default_serial_link(), workload)
    result.name = "serial"
    return result
