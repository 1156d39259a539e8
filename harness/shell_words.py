"""``~`` and ``$VAR`` in a path or command line the user gave, expanded as a shell would.

A shell expands ``~`` and ``$HOME`` in a word before the program sees it, but
not inside quotes: ``--node "python3 ~/lab07/fossbot_lidar_node.py"`` reaches
the harness with the ``~`` still in it, and so does every value in a
pytest.ini or a grading file, which no shell reads. The harness expands them
itself, in the options that name files and commands, with the part of a
shell's rules that makes sense there:

- ``~`` (``~user``) at the start of a word, up to its first ``/``;
- ``$NAME`` and ``${NAME}``, a variable's value taken as it is (one word: no
  splitting, no globbing); an unset variable is refused (`NotExpanded`), as
  ``set -u`` would, since an empty path is never what was meant;
- in a command line, quoting as `shlex.split` reads it: nothing inside single
  quotes or after a backslash is expanded, ``$`` inside double quotes is, ``~``
  is not;
- what only a shell can do (``$(...)``, backquotes, ``${NAME:-...}`` and other
  forms, ``$1``, ``$?``) is refused, with the fix. A ``$`` before anything else
  stays a ``$``.

Pure: no I/O but the environment and the user database.
"""

from __future__ import annotations

import os
import shlex
from collections.abc import Mapping

__all__ = ["NotExpanded", "expand_command", "expand_path"]

SPECIAL = set("0123456789?$#@*!-")  # $1, $?, $$ ...: a shell's, meaningless here
WHITESPACE = " \t\r\n"
ONLY_NAMES = "only $NAME and ${NAME} are expanded: write the value out"
NOT_RUN = (
    "is not run: the harness starts the command itself, without a shell; run it in your "
    "shell (outside the quotes), or write its output out"
)

# One character of a word and how it was written: "plain" (unquoted), "double" (inside
# double quotes: $ expands, ~ does not) or "literal" (single quotes, a backslash).
Char = tuple[str, str]


class NotExpanded(ValueError):
    """A word the harness will not expand: an unset variable, or what only a shell does."""


def _is_name_start(char: str) -> bool:
    return char == "_" or (char.isascii() and char.isalpha())


def _is_name_char(char: str) -> bool:
    return char == "_" or (char.isascii() and char.isalnum())


def _home(prefix: str, env: Mapping[str, str]) -> str:
    """``~`` ($HOME) or ``~user`` as a path; NotExpanded for a user this machine does not
    know."""
    if prefix == "~" and env.get("HOME"):
        return env["HOME"]
    home = os.path.expanduser(prefix)
    if home == prefix:
        user = prefix[1:]
        raise NotExpanded(f"{prefix}: no user {user!r} on this machine" if user else "~: no home")
    return home


def _variable(word: list[Char], i: int, env: Mapping[str, str]) -> tuple[str, int] | None:
    """The ``$`` at `word[i]` expanded, and the index after it; None: it is a plain ``$``."""
    kind = word[i][1]
    rest = [c for c, k in word[i + 1 :]]
    same = [k == kind for c, k in word[i + 1 :]]
    if not rest or not same[0]:
        return None  # "$" at the end, or before a quote: a $ (as POSIX shells read it)
    first = rest[0]
    if first == "(":
        raise NotExpanded(f"$(...) {NOT_RUN}")
    if first in SPECIAL:
        raise NotExpanded(f"${first}: {ONLY_NAMES}")
    if first == "{":
        end = next((j for j, c in enumerate(rest) if c == "}" and same[j]), None)
        if end is None:
            raise NotExpanded("${ without its closing }")
        name = "".join(rest[1:end])
        if not name or not _is_name_start(name[0]) or not all(map(_is_name_char, name)):
            raise NotExpanded(f"${{{name}}}: {ONLY_NAMES}")
        after = i + 1 + end + 1
    elif _is_name_start(first):
        length = 1
        while length < len(rest) and same[length] and _is_name_char(rest[length]):
            length += 1
        name = "".join(rest[:length])
        after = i + 1 + length
    else:
        return None
    if name not in env:
        raise NotExpanded(f"${name} is not set: set it (export {name}=...), or write the value out")
    return env[name], after


def _expand_word(word: list[Char], env: Mapping[str, str]) -> tuple[str, bool]:
    """A word's text once expanded, and whether anything in it was."""
    out: list[str] = []
    changed = False
    i = 0
    if word and word[0] == ("~", "plain"):
        end = next((j for j, (c, k) in enumerate(word) if c == "/" or k != "plain"), len(word))
        if end == len(word) or word[end][0] == "/":  # ~"user" is no tilde prefix
            out.append(_home("".join(c for c, _ in word[:end]), env))
            changed, i = True, end
    while i < len(word):
        char, kind = word[i]
        if kind != "literal" and char == "`":
            raise NotExpanded(f"`...` {NOT_RUN}")
        if kind != "literal" and char == "$":
            found = _variable(word, i, env)
            if found is not None:
                out.append(found[0])
                changed, i = True, found[1]
                continue
        out.append(char)
        i += 1
    return "".join(out), changed


def _words(text: str) -> list[tuple[list[Char], str]]:
    """`text` split into words as `shlex.split` splits it, each character with how it was
    quoted, and each word as written; ValueError (as shlex's) for an open quote or a
    backslash at the end."""
    words: list[tuple[list[Char], str]] = []
    word: list[Char] | None = None
    start = 0
    i, n = 0, len(text)
    while i < n:
        char = text[i]
        if char in WHITESPACE:
            if word is not None:
                words.append((word, text[start:i]))
                word = None
            i += 1
            continue
        if word is None:
            word, start = [], i
        if char == "\\":
            if i + 1 >= n:
                raise ValueError("No escaped character")
            word.append((text[i + 1], "literal"))
            i += 2
        elif char == "'":
            end = text.find("'", i + 1)
            if end < 0:
                raise ValueError("No closing quotation")
            word += [(c, "literal") for c in text[i + 1 : end]]
            i = end + 1
        elif char == '"':
            i += 1
            while i < n and text[i] != '"':
                if text[i] == "\\" and i + 1 < n:  # shlex: \" and \\ escape; else \ stays
                    kept = text[i + 1] if text[i + 1] in '"\\' else text[i : i + 2]
                    word += [(c, "literal") for c in kept]
                    i += 2
                else:
                    word.append((text[i], "double"))
                    i += 1
            if i >= n:
                raise ValueError("No closing quotation")
            i += 1
        else:
            word.append((char, "plain"))
            i += 1
    if word is not None:
        words.append((word, text[start:]))
    return words


def expand_command(text: str, env: Mapping[str, str] | None = None) -> str:
    """A command line (``--node``) with ``~`` and ``$VAR`` expanded where a shell would
    expand them, written so that `shlex.split` reads the words the shell would have passed
    (a word with nothing to expand as it was written).

    Unchanged when there is nothing to expand, or when it cannot be split at all (the
    command's own check says why); NotExpanded for what it will not expand.
    """
    if not any(c in text for c in "~$`"):
        return text
    try:
        words = _words(text)
    except ValueError:
        return text  # an open quote: split_command names it
    env = os.environ if env is None else env
    written: list[str] = []
    changed = False
    for word, as_written in words:
        value, changed_here = _expand_word(word, env)
        changed |= changed_here
        if not changed_here:
            written.append(as_written)
        elif value or not all(kind == "plain" for _, kind in word):  # "$EMPTY" alone: no word
            written.append(shlex.quote(value))
    return " ".join(written) if changed else text


def expand_path(text: str, env: Mapping[str, str] | None = None) -> str:
    """A path (or a name that may be one) with a leading ``~`` and ``$VAR`` expanded; the
    rest as it is (no quotes are read: a shell has removed them, or none was there)."""
    if not any(c in text for c in "~$`"):
        return text
    env = os.environ if env is None else env
    return _expand_word([(c, "plain") for c in text], env)[0]
