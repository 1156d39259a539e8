"""The suite checks itself: would the chosen scenarios catch the mistakes students make?

``mutants`` is the library of typical Lab 07 mistakes, each made on an
otherwise correct node (``mutant_node.py``, run as a student's node is);
``fossbot-hil audit`` runs each against the scenarios and shows which fail
it: a mutant no scenario fails is a mistake the suite cannot see.
"""

from harness import lazy_exports

_EXPORTS = {
    "Mutant": "mutants", "MUTANTS": "mutants", "mutant_named": "mutants",
    "mutant_command": "mutants",
}  # fmt: skip
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
