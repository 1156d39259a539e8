"""Text a student may see: no absolute path of the grader's machine, no hidden scenario's name.

Failures, build errors and notes are written on the instructor's machine (or
Gradescope's) and name its files: ``/home/ta/course/hidden/corridor.yaml``,
``/autograder/submission/lidar_node.py``. A student needs the file's name,
not where the grader keeps it, and must never learn a hidden scenario's name
or file. `for_students` is the one place that decides; a report writer still
escapes the result for its medium (harness.safe_text).

Pure (no rclpy, no pybullet). What counts as an absolute path: ``/`` (or
``~/``, or ``file://``) followed by at least two components, the first of
which is a top-level folder of a Unix machine (``home``, ``tmp``, ``usr``,
``autograder`` ..., or one that exists in this machine's ``/``). So a ROS 2
topic (``/scan``, ``/robot1/scan``) and a ratio (``m/s``) stay as they are.
A path in quotes may hold spaces; one that is not ends at a space, quote,
bracket, comma, colon or semicolon (``file.py:12`` keeps its line number).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from functools import cache

__all__ = ["for_students", "hide_names", "shorten_paths"]

#: Top-level folders of a Unix machine a grader's paths start with (besides those this
#: machine's / holds): FHS, macOS, CI runners, containers, Gradescope.
TOP_FOLDERS = frozenset(
    {
        "autograder",
        "bin",
        "boot",
        "builds",
        "data",
        "dev",
        "etc",
        "github",
        "home",
        "lib",
        "lib64",
        "media",
        "mnt",
        "nix",
        "opt",
        "private",
        "proc",
        "root",
        "run",
        "sbin",
        "scratch",
        "snap",
        "srv",
        "sys",
        "tmp",
        "Users",
        "usr",
        "var",
        "Volumes",
        "work",
        "workspace",
        "workspaces",
    }
)
_STOP = r"""\s'"`<>|;,:()\[\]{}"""  # a path without quotes ends at one of these
_QUOTED = re.compile(r"""(?P<q>['"`])(?P<path>(?:file://)?(?:~|/)[^'"`\n]*)(?P=q)""")
_BARE = re.compile(rf"(?<![\w./~-])(?P<path>(?:file://)?(?:~(?=/)|(?=/))(?:/[^{_STOP}/]+)+/?)")


@cache
def _machine_top_folders() -> frozenset[str]:
    """The folders in this machine's / (read once; none if / cannot be listed)."""
    try:
        return frozenset(e.name for e in os.scandir("/") if e.is_dir())
    except OSError:
        return frozenset()


def _file_name(path: str) -> str | None:
    """The file (or folder) name `path` ends with when it is an absolute path of a machine,
    else None (a topic, a relative path, a single component)."""
    path = path.removeprefix("file://")
    home = path.startswith("~/")
    parts = [p for p in path.removeprefix("~").split("/") if p]
    if not parts or (not home and len(parts) < 2):
        return None
    if not home and parts[0] not in TOP_FOLDERS and parts[0] not in _machine_top_folders():
        return None
    return parts[-1]


def shorten_paths(text: str) -> str:
    """Every absolute path of a machine in `text` replaced by its file name."""

    def quoted(match: re.Match[str]) -> str:
        name = _file_name(match["path"].rstrip("/"))
        return match.group() if name is None else f"{match['q']}{name}{match['q']}"

    def bare(match: re.Match[str]) -> str:
        name = _file_name(match["path"].rstrip("/"))
        return match.group() if name is None else name

    return _BARE.sub(bare, _QUOTED.sub(quoted, text))


def hide_names(text: str, hidden_names: Mapping[str, str]) -> str:
    """Each key of `hidden_names` (a hidden scenario's name, or its file's name or path)
    replaced by its value (the label students see), wherever it stands as a whole name:
    ``narrow_corridor``, ``narrow_corridor.yaml``, never inside ``narrow_corridor_2``.
    The longest key first, so a file's path goes before its name."""
    for key in sorted((k for k in hidden_names if k), key=len, reverse=True):
        label = hidden_names[key]
        if "/" in key:
            text = text.replace(key, label)
            continue
        suffix = "" if key.endswith((".yaml", ".yml")) else r"(?:\.ya?ml)?"
        pattern = re.compile(rf"(?<![\w-]){re.escape(key)}{suffix}(?![\w-])")
        text = pattern.sub(lambda _m, label=label: label, text)
    return text


def for_students(text: str, *, hidden_names: Mapping[str, str] | None = None) -> str:
    """`text` as a student may read it: a hidden scenario's name, file or path (the keys of
    `hidden_names`) as its label, every other absolute path as its file name.

    Not escaped for any medium: pass the result through harness.safe_text as usual.
    """
    hidden = dict(hidden_names or {})
    paths = {k: v for k, v in hidden.items() if "/" in k}
    text = hide_names(text, paths)  # a hidden file's whole path first: its name is hidden too
    return hide_names(shorten_paths(text), hidden)
