"""Hand-made scans of the gazebo preset's layout, for the pure tests of the judge."""

from __future__ import annotations

import math

import numpy as np

from harness.lidar.scan import Scan

N = 360
INC = 2 * math.pi / (N - 1)  # the gazebo preset: -pi..pi inclusive


def make_scan(values: dict[int, float] | None = None, fill: float = math.inf, **kw) -> Scan:
    """A gazebo-like scan: `fill` everywhere, `values` at given beams; `kw` overrides
    LaserScan fields (angle_min, range_min, ...)."""
    r = np.full(N, fill, np.float32)
    for i, v in (values or {}).items():
        r[i] = v
    fields = dict(
        angle_min=-math.pi,
        angle_max=math.pi,
        angle_increment=INC,
        time_increment=0.1 / N,
        scan_time=0.1,
        range_min=0.12,
        range_max=12.0,
    )
    fields.update(kw)
    return Scan(ranges=r, **fields)
