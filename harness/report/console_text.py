"""External text on a rich console, safely: a light module, so a command's parser can
import it without the report's heavier imports (pydantic, numpy)."""

from __future__ import annotations

from rich.console import Console

from harness.safe_text import TEXT_LIMIT, clip, for_terminal


def print_safe(
    console: Console, text: str, *, style: str = "", limit: int | None = TEXT_LIMIT
) -> None:
    """External text on the terminal: escaped, bounded (unless `limit` is None), no markup."""
    shown = for_terminal(text if limit is None else clip(text, limit))
    console.print(shown, style=style, markup=False, highlight=False, soft_wrap=True)
