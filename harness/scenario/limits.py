"""What one scenario may ask for (pure numbers).

Each bound keeps a hostile or mistaken file from hanging or exhausting the
machine; docs/scenarios.md ("Limits") lists them for users.
"""

from __future__ import annotations

# What one scenario may ask for. Each bound keeps a hostile or mistaken file
# from hanging or exhausting the machine; the lab's scenarios use a small
# fraction of each (docs/scenarios.md, "Limits").
MAX_FILE_BYTES = 1 << 20  # a scenario file
MAX_YAML_DEPTH = 20  # nesting of YAML mappings and lists (aliases expanded)
MAX_YAML_NODES = 100_000  # values in the file, each alias counted at its full size
MAX_YAML_SCALAR = 4096  # characters of one YAML value
MAX_SEGMENT_SECONDS = 600.0  # one segment's duration or timeout
MAX_RUN_SECONDS = 600.0  # simulated time of a whole run, conditional segments at their timeout
MAX_SCANS = 10_000  # LIDAR revolutions of a whole run
MAX_RAYS = 10_000_000  # beams cast in a whole run (scans x samples)
MAX_CYLINDER_SIDES = 100_000  # sides of all cylinder meshes together (big radii need more)
MAX_MODELS = 100  # model (URDF/SDF) obstacles
MAX_COORDINATE = 1000.0  # m, |x| and |y| of anything placed in the world
MIN_SIZE, MAX_SIZE = 0.001, 100.0  # m, sizes of walls, boxes and cylinders
MAX_RANGE = 100.0  # m, LIDAR range_max, the threshold and obstacle conditions
MAX_PATH = 1024  # characters of a model path
START_OVERLAP = 0.005  # m the robot may overlap an obstacle where it starts (touching, rounding)
