"""One typed run request: the run options, declared once, and the request that checks them.

`table` holds one row per option (its key, how a value is read, its
default and help, and how each caller names it: a CLI flag, a ``--hil-*``
option and ini key, a grading-file field). `RunRequest` is built from any
caller's values, checks itself once and raises `OptionError`, which each
caller renders with its own names for the keys. Pure: no rclpy, no pybullet.
"""

from __future__ import annotations

from harness.errors import OptionError
from harness.option_names import Names
from harness.run_request.request import RunRequest
from harness.run_request.table import OPTIONS, RunOption, option

__all__ = ["OPTIONS", "Names", "OptionError", "RunOption", "RunRequest", "option"]
