"""A virtual environment without pip that sees this project's installed packages.

What a fresh machine's venv would hold, without installing it again: the
tests that run a CI template's or an autograder's steps make one and let the
steps install (or find) what they need in it.
"""

from __future__ import annotations

import subprocess
import sys
import sysconfig
from pathlib import Path


def borrowing_venv(where: Path, pth_name: str = "_borrows_project.pth") -> Path:
    """`where`, a venv whose site-packages adds this interpreter's (through `pth_name`)."""
    subprocess.run(
        [sys.executable, "-m", "venv", "--without-pip", str(where)], check=True, timeout=60
    )
    python = where / "bin" / "python"
    purelib = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
        timeout=30,
    ).stdout.strip()
    project = sysconfig.get_paths()["purelib"]
    Path(purelib, pth_name).write_text(f"import site; site.addsitedir({project!r})\n")
    return where
