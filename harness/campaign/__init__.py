"""Test campaigns: one node through every combination of scenarios, faults, seeds, thresholds.

- ``plan``: the runs, each with a stable key;
- ``task``: one run as a Dask task, returning its results row;
- ``results``: the CSV table, a row written durably as each run finishes,
  read back by ``--resume``;
- ``factors``: which factors the failures depend on, in plain words.

The runs go to a Dask cluster (``harness.cluster``), embedded or external.
"""
