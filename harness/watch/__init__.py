"""`fossbot-hil run --watch` and `--failed-first`: the edit-run loop.

``sources`` (pure: what to watch, whether a change needs a build),
``changes`` (the watcher), ``rebuild`` (colcon), ``verdict_cache`` and
``order`` (failed first), ``screen``, and ``loop``, which joins them.
"""

from harness import lazy_exports

_EXPORTS = {
    "ChangeFeed": "changes", "WatchLoop": "loop", "WatchScreen": "screen", "failed_first": "order",
}  # fmt: skip
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
