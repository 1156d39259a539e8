"""The fossbot-hil pytest plugin: scenarios as tests, the ``hil`` fixture, board runs
(docs/pytest.md is the user's guide)."""

from harness import lazy_exports

_EXPORTS = {
    "NodeUnderTest": "plugin", "HilBoard": "plugin", "HilCase": "cases", "Hil": "hil",
    "HilResult": "result",
}  # fmt: skip
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
