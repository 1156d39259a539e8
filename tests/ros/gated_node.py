#!/usr/bin/env python3
"""The reference node, started only once a gate file exists: a run held open on purpose.

Run as ``python3 gated_node.py GATE --ros-args ...``. It waits (at most a
minute) for GATE to appear, then becomes the bundled reference node with
the remaining arguments, so the run it belongs to then passes. A test holds
one run at its start this way while it starts a second one beside it.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

gate = Path(sys.argv[1])
deadline = time.monotonic() + 60
while not gate.exists() and time.monotonic() < deadline:
    time.sleep(0.02)  # polling a bounded condition the test controls
os.execv(sys.executable, [sys.executable, "-m", "harness.reference.lidar_node", *sys.argv[2:]])
