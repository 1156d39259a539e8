"""The suite checks itself: would the chosen scenarios catch the mistakes students make?

- ``mutants``: the library of typical Lab 07 mistakes ("mutants"), each one
  mistake made on an otherwise correct node (``Mutant``, ``MUTANTS``), and
  the command line that starts one (``mutant_command``);
- ``mutant_node.py``: that node, one executable script that makes the
  mistake its first argument names (``correct``, the control, makes none).
  It imports only rclpy, the message packages, numpy and the standard
  library, and runs as a student's node does, in its own process.

``fossbot-hil audit`` runs every mutant against the chosen scenarios and
shows the kill matrix: which scenarios fail each mutant. A mutant that no
scenario fails is a mistake the suite cannot see.
"""

from harness import lazy_exports

_EXPORTS = {
    "Mutant": "mutants",
    "MUTANTS": "mutants",
    "mutant_named": "mutants",
    "mutant_command": "mutants",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
