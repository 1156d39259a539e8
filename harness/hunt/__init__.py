"""Hunting for the simplest scenario a node fails (``fossbot-hil hunt``, docs/hunt.md).

- ``space``: a candidate scenario (one obstacle, one motion, the LIDAR preset,
  the driver's convention, a sensor fault, the threshold) and its file;
- ``margin``: how close a run came to failing, and how it failed;
- ``task``: one candidate's run as a Dask task;
- ``search``: the seeded optimiser, in fixed batches, then confirm and shrink;
- ``shrink``: simpler versions of a failing candidate.
"""
