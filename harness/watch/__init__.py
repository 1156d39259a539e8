"""`fossbot-hil run --watch` and `--failed-first`: the edit-run loop.

- ``order``: failed scenarios first, then the rest in their given order;
- ``verdict_cache``: each run's verdicts per scenario, kept between
  commands in the user's cache folder (what `--failed-first` reads);
- ``changes``: the file watcher (watchfiles), in background threads, so a
  change saved while a run goes is kept for the next;
- ``rebuild``: ``colcon build`` of the package under test, bounded;
- ``screen``: one compact screen that redraws on a terminal, plain lines
  elsewhere;
- ``loop``: run, wait for a change, (build,) run again, until Ctrl-C.

- ``sources`` (pure): what to watch for a node (its script, a workspace
  package's sources, a processor file, scenario files), and whether a change
  needs a ``colcon build``.
"""

from harness import lazy_exports

_EXPORTS = {
    "ChangeFeed": "changes",
    "WatchLoop": "loop",
    "WatchScreen": "screen",
    "failed_first": "order",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
