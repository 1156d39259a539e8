"""Ending a process as the interpreter would, without its teardown.

The `fossbot-hil` command and a node forked by the node fork server both end
this way: the exit handlers run and the output is flushed, then the process
exits at once. Freeing memory would take a quarter of a second with rclpy
and PyBullet loaded, and nothing is left to write by then.
"""

from __future__ import annotations

import atexit
import os
import sys
from typing import NoReturn


def finish_interpreter() -> None:
    """What the interpreter does on exit that code may rely on: atexit handlers, flushed
    stdout and stderr (a closed pipe or a failing handler is not ours to report)."""
    try:
        atexit._run_exitfuncs()
    except BaseException:  # the interpreter reports such a handler and goes on; so do we
        pass
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass


def exit_now(code: int) -> NoReturn:
    """`finish_interpreter`, then exit with `code` without the teardown."""
    finish_interpreter()
    os._exit(code)
