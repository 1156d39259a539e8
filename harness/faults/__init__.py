"""How a scan is spoiled: seeded faults of the sensor and of the link (pure).

``sensor``: what the LIDAR and its driver get wrong (``build_profile`` reads
a ``faults:`` list); ``link``: how scans travel (late, lost, twice, stale)
and serial bytes are damaged. Same seed, same faults. Add one in its module
(and docs/faults.md).
"""

from harness import lazy_exports

_EXPORTS = {
    "FaultProfile": "sensor",
    "build_profile": "sensor",
    "LinkFaults": "link",
    "Delivery": "link",
    "NO_LINK_FAULTS": "link",
    "plan_deliveries": "link",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
