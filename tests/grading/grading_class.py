"""A small class of students, made from the reference package with real bugs patched in."""

from __future__ import annotations

import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
REFERENCE = REPO / "node" / "fossbot_lidar_processing"
STUDENT_NODE = REPO / "tests" / "ros" / "student_node.py"
PACKAGE = "fossbot_lidar_processing"
LAB_SCENARIOS = ("approach_wall", "drive_past_10m", "out_of_range")


def copy_package(target: Path) -> Path:
    """The reference package's sources (no caches) at `target`."""
    shutil.copytree(
        REFERENCE, target, ignore=shutil.ignore_patterns(".ruff_cache", "__pycache__", "*.egg-info")
    )
    return target


def patch(path: Path, old: str, new: str) -> None:
    """Replace `old` (which must be there) by `new`: the student's bug."""
    text = path.read_text()
    assert old in text, f"{path} no longer contains {old!r}"
    path.write_text(text.replace(old, new))


def good_workspace(folder: Path) -> Path:
    """A colcon workspace with the reference package under src/."""
    copy_package(folder / "src" / PACKAGE)
    return folder


def range_min_bug_package(folder: Path) -> Path:
    """A package (package.xml at the top) that forgets range_min: out_of_range catches it."""
    copy_package(folder)
    patch(
        folder / PACKAGE / "scan_logic.py",
        "np.isfinite(values) & (values >= low) & (values <= high)",
        "np.isfinite(values) & (values <= high)",
    )
    return folder


def broken_setup_package(folder: Path) -> Path:
    """A package whose setup.py lacks a comma: colcon cannot even read it."""
    copy_package(folder)
    patch(folder / "setup.py", "version='0.1.0',", "version='0.1.0'")
    return folder


def script_student(folder: Path) -> Path:
    """One .py file, as a student without a package hands in (the correct variant)."""
    folder.mkdir(parents=True)
    (folder / "lidar_node.py").write_text(  # the test suite's student node, correct variant
        'import sys\n\nsys.argv[1:1] = ["correct"]\n' + STUDENT_NODE.read_text()
    )
    return folder


def snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    """Every file below `folder` with its size and mtime: building must change none."""
    return {
        str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
        for p in sorted(folder.rglob("*"))
    }
