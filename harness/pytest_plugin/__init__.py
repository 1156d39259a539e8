"""The fossbot-hil pytest plugin: scenarios as tests, the ``hil`` fixture, board runs.

- ``plugin``: the hooks and fixtures pytest loads (entry point ``fossbot_hil``);
- ``options``: its options, from the command line, then the ini file, then
  the default;
- ``cases``: ``@pytest.mark.hil_scenarios``, one test per scenario and fault
  profile;
- ``hil``: the ``hil`` fixture's object, which runs one scenario and judges it;
- ``result``: what ``hil.run`` returns, with what a failing test needs to say.

docs/pytest.md is the user's guide.
"""

from harness import lazy_exports

_EXPORTS = {
    "NodeUnderTest": "plugin",
    "HilBoard": "plugin",
    "HilCase": "cases",
    "Hil": "hil",
    "HilResult": "result",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
