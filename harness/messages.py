"""Text from users inside one-line error messages (pure).

File names, YAML keys and model link names can hold newlines and terminal
escape sequences; printed raw they would break the "one line on stderr"
promise or recolour a terminal. ``shown`` makes any of them safe to print.
"""

from __future__ import annotations

__all__ = ["shown"]


def shown(text: str, limit: int = 200) -> str:
    """`text` for a one-line message: non-printable characters escaped, long text shortened."""
    if not text.isprintable():
        text = repr(text)[1:-1]
    if len(text) > limit:
        text = f"{text[: limit // 2]}...{text[-(limit // 4) :]}"
    return text
