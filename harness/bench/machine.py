"""Where the bench ran: CPU, cores, Python, OS, load, and the peak memory used.

Figures from one machine only compare with figures from the same machine
under a similar load, so every report carries this.
"""

from __future__ import annotations

import os
import platform
import resource
from importlib import metadata
from pathlib import Path

PACKAGES = ("pybullet", "numpy", "ros-jazzy-rclpy", "rplidar")


def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo on Linux), else what platform knows."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def load_average() -> list[float] | None:
    """1, 5 and 15 minute load averages (None where the OS has none)."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def _version(name: str) -> str | None:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


def describe() -> dict[str, object]:
    """The machine object of the bench's JSON."""
    return {
        "cpu": cpu_model(),
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "os": platform.platform(),
        "packages": {name: _version(name) for name in PACKAGES},
    }


def peak_rss_mb() -> float:
    """Peak resident memory of this process (``ru_maxrss``), MB. Not ``RUSAGE_CHILDREN``:
    a forked child keeps the parent's mark from before its exec; the bench reads the
    nodes' own ``VmHWM`` while they run."""
    scale = 1.0 if platform.system() == "Darwin" else 1024.0  # macOS reports bytes, Linux KiB
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * scale / 1e6
