"""The inprocess link: call a Python processing function directly, no ROS.

The reference solution's pure logic by default, or any
``fn(scan, threshold) -> (status_text, warning_or_None)`` named as
``module:function`` or ``path/to/file.py:function``. It runs the whole loop
in milliseconds, which is how the scenarios themselves are checked.
"""

from __future__ import annotations

import importlib
import importlib.util
import time
import traceback
from collections.abc import Callable
from pathlib import Path

from harness.answers import Answers, Received
from harness.errors import ConfigError
from harness.links.base import Link, LinkOptions, register
from harness.scan import Scan

Processor = Callable[[Scan, float], "tuple[str, bool | None]"]


def reference_processor(scan: Scan, threshold: float) -> tuple[str, bool | None]:
    """The lab's full solution, as the bundled ROS 2 node runs it."""
    from harness.reference.scan_logic import analyse_message, status_text

    report = analyse_message(scan, threshold)
    return status_text(report), report.warning


def load_processor(ref: str) -> Processor:
    """Resolve ``module:function`` or ``file.py:function`` to a callable."""
    target, sep, attr = ref.rpartition(":")
    if not sep or not target or not attr:
        raise ConfigError(f"--processor {ref!r}: expected MODULE:FUNCTION or FILE.py:FUNCTION")
    try:
        if target.endswith(".py"):
            path = Path(target)
            if not path.is_file():
                raise ConfigError(f"--processor {ref!r}: no such file {target}")
            spec = importlib.util.spec_from_file_location(f"_processor_{path.stem}", path)
            assert spec is not None and spec.loader is not None
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(target)
    except ConfigError:
        raise
    except Exception as err:  # the user's module failing to import is their error
        raise ConfigError(f"--processor {ref!r}: cannot import: {err}") from None
    fn = getattr(module, attr, None)
    if not callable(fn):
        raise ConfigError(f"--processor {ref!r}: {target} has no function {attr!r}")
    return fn


@register("inprocess")
class InprocessLink(Link):
    """Feed each scan to a Python function in this process."""

    def __init__(self, options: LinkOptions) -> None:
        super().__init__(options)
        self._process = (
            load_processor(options.processor) if options.processor else reference_processor
        )
        self._pending: Answers | None = None

    def send(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        started = time.perf_counter()
        try:
            text, warning = self._process(scan, self.options.threshold)
        except Exception as err:
            where = traceback.extract_tb(err.__traceback__)[-1]
            self._pending = Answers(
                problem=f"processing function raised {type(err).__name__}: {err} "
                f"({Path(where.filename).name}:{where.lineno})"
            )
            return
        after = time.perf_counter() - started
        answers = Answers(statuses=[Received(str(text), after)], waited=after)
        if warning is not None:
            answers.warnings.append(Received(bool(warning), after))
        self._pending = answers

    def hold(self, seconds: float) -> None:
        """A delay changes nothing for a function called in lockstep: no wall time is spent."""

    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        answers, self._pending = self._pending, None
        return answers if answers is not None else Answers(timed_out=True)
