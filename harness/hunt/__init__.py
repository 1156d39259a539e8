"""Hunting for the simplest scenario a node fails (``fossbot-hil hunt``, docs/hunt.md).

``space`` (the candidates), ``margin`` (how close a run came), ``search`` (the
seeded optimiser), ``shrink`` (simpler failing versions), ``task`` (one run).
"""
