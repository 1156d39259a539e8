"""Text from outside the harness, made safe for where it lands (pure).

A node under test, a student's processing function or a scenario file
decides what its status strings, stderr, topic names and scenario names
contain: escape sequences that drive a terminal, carriage returns that
overwrite a line, bidi overrides, NUL and lone surrogates (invalid in XML
1.0 and in UTF-8), or a megabyte per message. Every report writer passes
such text through this module, so there is one place that decides what is
safe per medium:

- ``clip``: long text shortened, its length noted (what records keep);
- ``for_storage``: clipped and encodable as UTF-8 (JSON, MCAP);
- ``visible``: every non-printable character as a visible escape
  (``\\x1b``, ``\\u202e``, ``\\ud800``); newline and tab stay. Its result
  is safe on a terminal and valid in XML 1.0;
- ``for_terminal``, ``for_xml``, ``for_html``, ``for_csv``: per medium.
  A terminal writer must still print with markup off (or as rich Text);
- ``shown``: a file name, YAML key or model link name quoted inside a
  one-line error message.
"""

from __future__ import annotations

import html
import re

__all__ = [
    "DIAGNOSTICS_LIMIT",
    "QUOTE_LIMIT",
    "TEXT_LIMIT",
    "clip",
    "for_csv",
    "for_html",
    "for_storage",
    "for_terminal",
    "for_xml",
    "shown",
    "visible",
]

TEXT_LIMIT = 4096  # characters of one external text kept in a record (a status, an error)
DIAGNOSTICS_LIMIT = 4 * TEXT_LIMIT  # the node's output tails and notes, in all
QUOTE_LIMIT = 200  # characters of a status quoted inside an explanation
CSV_FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")  # a spreadsheet would run these

_KEPT = "\n\t"
_SURROGATE = re.compile("[\ud800-\udfff]")


def clip(text: str, limit: int = TEXT_LIMIT) -> str:
    """`text` if it has at most `limit` characters, else its start and a note of its length.

    The result never exceeds `limit` characters, so clipping twice changes
    nothing: ``'xxxx… [1048576 characters; 1044520 not kept]'``.
    """
    if len(text) <= limit:
        return text
    longest = f"… [{len(text)} characters; {len(text)} not kept]"
    kept = max(0, limit - len(longest))
    return f"{text[:kept]}… [{len(text)} characters; {len(text) - kept} not kept]"


def _escape(char: str) -> str:
    return repr(char)[1:-1]  # a non-printable character: \x1b, \r, \u202e, \ud800, ...


def visible(text: str) -> str:
    """Every character that is not printable (``str.isprintable``) as its Python escape.

    Newline and tab stay as they are. Nothing in the result can move a
    terminal's cursor, change its colours or reorder a line, and every
    character is allowed in XML 1.0.
    """
    if text.replace("\n", "").replace("\t", "").isprintable():
        return text
    return "".join(c if c.isprintable() or c in _KEPT else _escape(c) for c in text)


def for_storage(text: str, limit: int = TEXT_LIMIT) -> str:
    """Clipped, and any lone surrogate as its escape: any UTF-8 file (JSON, MCAP) holds it.

    Otherwise the text stays exact (JSON escapes control characters itself).
    """
    return _SURROGATE.sub(lambda m: _escape(m.group()), clip(text, limit))


def for_terminal(text: str) -> str:
    """For a terminal (or a log): `visible`. Print it with markup off, or as rich Text."""
    return visible(text)


def for_xml(text: str) -> str:
    """For an XML attribute or text node; the XML writer escapes ``<&"`` itself."""
    return visible(text)


def for_html(text: str) -> str:
    """For HTML text and attribute values: visible, then escaped (quotes too)."""
    return html.escape(visible(text), quote=True)


def for_csv(text: str) -> str:
    """A CSV cell that a spreadsheet shows as text, never runs as a formula."""
    text = visible(text)
    return f"'{text}" if text.startswith(CSV_FORMULA_STARTS) else text


def shown(text: str, limit: int = 200, *, quoted: bool = False) -> str:
    """`text` for a one-line message: non-printable characters escaped, long text shortened.

    `quoted`: in quotes, as ``repr`` writes it, for a name whose spaces or
    emptiness the reader must see (a topic, a parameter rule); cut at the end.
    """
    if quoted:
        text = repr(text)
        return text if len(text) <= limit else f"{text[: limit - 4]}...{text[-1]}"
    if not text.isprintable():
        text = repr(text)[1:-1]
    if len(text) > limit:
        text = f"{text[: limit // 2]}...{text[-(limit // 4) :]}"
    return text
