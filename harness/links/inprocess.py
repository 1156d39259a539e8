"""The inprocess link: call a Python processing function directly, no ROS.

The reference's pure logic by default, or any ``fn(scan, threshold) -> (status_text,
warning_or_None)`` named as ``module:function`` or ``path/to/file.py:function``."""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable
from pathlib import Path

from harness.errors import ConfigError, OptionError
from harness.judge.answers import Answers, Received
from harness.lidar.scan import Scan
from harness.links.base import Link, LinkOptions, register
from harness.links.processor_child import ProcessorChild

DIAGNOSTIC_LINES = 14  # with the heading, what the terminal summary shows

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
        raise OptionError.saying(
            "processor", f"{ref!r}: expected MODULE:FUNCTION or FILE.py:FUNCTION"
        )
    try:
        if target.endswith(".py"):
            path = Path(target)
            if not path.is_file():
                raise OptionError.saying("processor", f"{ref!r}: no such file {target}")
            spec = importlib.util.spec_from_file_location(f"_processor_{path.stem}", path)
            assert spec is not None and spec.loader is not None
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(target)
    except ConfigError:
        raise
    except Exception as err:  # the user's module failing to import is their error
        raise OptionError.saying("processor", f"{ref!r}: cannot import: {err}") from None
    fn = getattr(module, attr, None)
    if not callable(fn):
        raise OptionError.saying("processor", f"{ref!r}: {target} has no function {attr!r}")
    return fn


@register("inprocess")
class InprocessLink(Link):
    """Feed each scan to a Python function in a forked child (``processor_child``): no ROS,
    and raising, exiting, hanging or crashing ends the run as an ERROR, never a pass."""

    def __init__(self, options: LinkOptions) -> None:
        super().__init__(options)
        self._process = (
            load_processor(options.processor) if options.processor else reference_processor
        )
        self._child: ProcessorChild | None = None

    def open(self) -> None:
        self._child = ProcessorChild(self._process)
        self._child.start()

    def send(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        assert self._child is not None, "open() the link first"
        self._child.call(scan, self.options.threshold)

    def hold(self, seconds: float) -> None:
        """A delay changes nothing for a function called in lockstep: no wall time is spent."""

    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        assert self._child is not None, "open() the link first"
        outcome = self._child.outcome(self.options.scan_timeout)
        if outcome.problem is not None:  # raised, hung, exited: the function's, not the link's
            return Answers(problem=outcome.problem, crashed=True)
        after = outcome.seconds
        answers = Answers(statuses=[Received(outcome.status or "", after)], waited=after)
        if outcome.warning is not None:
            answers.warnings.append(Received(outcome.warning, after))
        return answers

    def diagnostics(self) -> str:
        """What the function printed (stdout and stderr), last lines; the child is stopped
        first, so all it wrote is in."""
        if self._child is None:
            return ""
        self._child.close()
        tail = self._child.output_tail(DIAGNOSTIC_LINES)
        return f"processing function output:\n{tail}" if tail else ""

    def close(self) -> None:
        if self._child is not None:
            self._child.close()
