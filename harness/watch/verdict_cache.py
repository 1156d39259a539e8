"""The last run's verdicts per scenario, for `run --failed-first` and `run --watch`.

As `pytest --ff` reads .pytest_cache, but kept in the user's cache folder
(harness.user_cache), not the working folder: that is often a student's
repository they hand in, or not writable. One file per working folder and
node under test (named by a hash of both): another node's verdicts, or the
same command line's from another folder, say nothing of this one's. The
file only orders scenarios, never judges them: a missing or unusable file
means the given order.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from harness.atomic_write import write_atomically
from harness.user_cache import cache_root

if TYPE_CHECKING:
    from harness.judge.records import RunResult
    from harness.links.base import LinkOptions

__all__ = ["VerdictCache", "cache_folder", "node_key", "verdict_cache"]

FORMAT = 1
KEPT_FILES = 200
PASSED, FAILED = "passed", "failed"


def cache_folder(env: Mapping[str, str] | None = None) -> Path:
    """``last-run`` in the user's cache folder (``harness.user_cache``)."""
    return cache_root(env) / "last-run"


def node_key(link: str, options: LinkOptions, cwd: str | None = None) -> dict[str, object]:
    """What names the node under test, and where the command ran (its relative paths)."""
    workspace = os.path.abspath(options.workspace) if options.workspace else None
    return {
        "cwd": cwd if cwd is not None else os.getcwd(),
        "link": link,
        "node": options.node,
        "package": options.package,
        "executable": options.executable,
        "workspace": workspace,
        "processor": options.processor,
        "board_commands": list(options.board_commands),
    }


@dataclass(frozen=True)
class VerdictCache:
    """The verdicts file of one working folder and node."""

    path: Path
    key: Mapping[str, object]

    def verdicts(self) -> dict[str, str]:
        """Scenario name -> "passed" or "failed"; empty when there is no usable file."""
        try:
            stored = json.loads(self.path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return {}
        ours = isinstance(stored, dict) and stored.get("format") == FORMAT
        verdicts = stored.get("verdicts") if ours and stored.get("key") == dict(self.key) else None
        if not isinstance(verdicts, dict):
            return {}
        return {
            name: verdict
            for name, verdict in verdicts.items()
            if isinstance(name, str) and verdict in (PASSED, FAILED)
        }

    def failed(self) -> set[str]:
        """The scenarios that failed when they last ran."""
        return {name for name, verdict in self.verdicts().items() if verdict == FAILED}

    def remember(self, results: Sequence[RunResult], *, interrupted: bool = False) -> None:
        """Keep this run's judged verdicts (not the scenario an `interrupted` run stopped
        in) over the earlier ones; a file that cannot be written is no error."""
        judged = [r for r in results if not r.not_run]
        if interrupted and judged:
            judged = judged[:-1]
        verdicts = self.verdicts()
        for result in judged:
            verdicts[result.scenario] = PASSED if result.ok else FAILED
        content = {"format": FORMAT, "key": dict(self.key), "verdicts": verdicts}
        data = json.dumps(content, indent=1, sort_keys=True).encode("utf-8") + b"\n"
        with contextlib.suppress(OSError):
            write_atomically(self.path, data)
            _keep_newest(self.path.parent, KEPT_FILES)


def _keep_newest(folder: Path, count: int) -> None:
    """Remove all but the `count` most recently written verdict files."""
    files = []
    for path in folder.glob("*.json"):
        with contextlib.suppress(OSError):
            files.append((path.stat().st_mtime, path))
    for _, path in sorted(files, reverse=True)[count:]:
        with contextlib.suppress(OSError):
            path.unlink()


def verdict_cache(
    link: str, options: LinkOptions, *, cwd: str | None = None, folder: Path | None = None
) -> VerdictCache:
    """The verdicts file for this node run from this folder."""
    key = node_key(link, options, cwd)
    digest = hashlib.sha256(json.dumps(key, sort_keys=True).encode("utf-8")).hexdigest()
    return VerdictCache((folder or cache_folder()) / f"{digest[:24]}.json", key)
