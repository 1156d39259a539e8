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
    (folder / "lidar_node.py").write_text(
        "import runpy\nimport sys\n\n"
        "# the test suite's student node, correct variant\n"
        'sys.argv[1:1] = ["correct"]\n'
        f'runpy.run_path({str(STUDENT_NODE)!r}, run_name="__main__")\n'
    )
    return folder


def snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    """Every file below `folder` with its size and mtime: building must change none."""
    return {
        str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
        for p in sorted(folder.rglob("*"))
    }


# Single-file students for grading on a cluster (tests/grading/test_grading_cluster.py,
# benchmarks/cluster_throughput.py): VARIANT.format(variant=...) runs a student_node variant.
VARIANT = (
    "import runpy\nimport sys\n\n"
    'sys.argv[1:1] = ["{variant}"]\n'
    f'runpy.run_path({str(STUDENT_NODE)!r}, run_name="__main__")\n'
)
HANGS = (
    "import signal\nimport time\n\n"
    "signal.signal(signal.SIGTERM, signal.SIG_IGN)  # and never comes up\n"
    "while True:\n    time.sleep(1)\n"
)
# Walks up its ancestors to the Dask worker process (a nanny's spawned child, or a
# `dask worker --no-nanny`) and kills it, as a node gone badly wrong might.
KILLS_ITS_WORKER = """\
import os
import signal

pid = os.getppid()
while pid > 1:
    with open(f"/proc/{pid}/cmdline", "rb") as handle:
        command = handle.read().replace(b"\\0", b" ")
    if b"spawn_main" in command or b"dask_worker" in command:
        os.kill(pid, signal.SIGKILL)
        break
    with open(f"/proc/{pid}/stat", "rb") as handle:
        pid = int(handle.read().rsplit(b")", 1)[1].split()[1])
"""
