"""Test campaigns: one node through every combination of scenarios, faults, seeds, thresholds.

``plan`` (the runs, each with a stable key), ``task`` (one run as a Dask
task), ``results`` (the CSV, a row durable as each run ends, read back by
``--resume``), ``factors`` (what the failures depend on, in plain words).
"""
