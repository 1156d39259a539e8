"""Fixtures of the serial-link tests: the far end of a null-modem cable (far_end.py)."""

from far_end import far_end

__all__ = ["far_end"]
