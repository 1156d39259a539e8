"""How a scan is spoiled: seeded faults of the sensor and of the link (pure).

- ``sensor``: what the LIDAR gets wrong (noise, dropouts, spurious returns)
  and how its driver writes no-return (REP-117 or a real driver's
  convention); ``build_profile`` reads a fault list into a ``FaultProfile``;
- ``link``: what happens on the way to the node: late, dropped, doubled,
  reordered or stale scans, a drifting rate, and damage on a serial line.

Same seed, same faults. Add a sensor fault in ``sensor`` or a link fault in
``link`` (and docs/faults.md).
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
