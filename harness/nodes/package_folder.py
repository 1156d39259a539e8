"""Where a ROS package's sources sit in a colcon workspace, found as colcon finds them.

`run --watch` watches that folder and the launch-file check reads its
``launch/`` folder; both must agree with colcon on which folder is the
package (not a copy under build/ or install/).
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

__all__ = ["WORKSPACE_OUTPUTS", "find_package", "package_name"]

WORKSPACE_OUTPUTS = ("build", "install", "log")  # colcon's folders in a workspace


def _hidden(name: str) -> bool:
    """An editor's or a tool's own file (.#node.py, .node.py.swp, .git, .ruff_cache)."""
    return name.startswith((".", "~"))


def package_name(package_xml: Path) -> str | None:
    """The <name> a package.xml gives (None when unreadable)."""
    try:
        name = ET.parse(package_xml).getroot().findtext("name")
    except (OSError, ET.ParseError):
        return None
    return name.strip() if name else None


def find_package(workspace: Path, package: str) -> Path | None:
    """The folder under `workspace` whose package.xml names `package`, as colcon finds
    it: not in the workspace's build/, install/ or log/, nor in hidden folders or
    folders holding a COLCON_IGNORE; symlinked folders are followed (once each)."""
    seen: set[Path] = set()
    for folder, subfolders, files in os.walk(workspace, followlinks=True):
        here = Path(folder)
        real = Path(os.path.realpath(here))
        if real in seen or "COLCON_IGNORE" in files:
            subfolders[:] = []
            continue
        seen.add(real)
        if "package.xml" in files and package_name(here / "package.xml") == package:
            return here
        skip = WORKSPACE_OUTPUTS if here == workspace else ()
        subfolders[:] = sorted(
            d for d in subfolders if d not in skip and not _hidden(d) and d != "__pycache__"
        )
    return None
