"""One typed run request: the run options, declared once (``table``), and the
`RunRequest` that checks them once, raising `OptionError` that each caller words with
its own names (pure)."""

from __future__ import annotations

from harness.errors import OptionError
from harness.option_names import Names
from harness.run_request.request import RunRequest
from harness.run_request.table import OPTIONS, RunOption, option

__all__ = ["OPTIONS", "Names", "OptionError", "RunOption", "RunRequest", "option"]
