"""Ending a process as the interpreter would, without its teardown: exit handlers run
and output is flushed, but freeing memory (a quarter of a second with rclpy and
PyBullet loaded) is skipped."""

from __future__ import annotations

import atexit
import contextlib
import os
import sys
from typing import NoReturn


def finish_interpreter() -> None:
    """What the interpreter does on exit that code may rely on: atexit handlers, flushed
    stdout and stderr (a closed pipe or a failing handler is not ours to report)."""
    with contextlib.suppress(BaseException):  # the interpreter goes on past a failing one too
        atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()


def exit_now(code: int) -> NoReturn:
    """`finish_interpreter`, then exit with `code` without the teardown."""
    finish_interpreter()
    os._exit(code)
