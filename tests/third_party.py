"""Third-party clients that cannot live in the test venv, installed once per machine.

rplidar-roboticia 0.9.5 (what the real FOSSBot v2 reads its A1 with)
installs a module named ``rplidar``, as the PyPI ``rplidar`` 0.9.2 in the
venv does, so it goes into a folder of its own that a client process puts
on its PYTHONPATH. The folder is kept under the user's cache
(``$XDG_CACHE_HOME``, else ``~/.cache``) in ``fossbot-hil-tests/``: pip
installs into a temporary folder there, renamed into place whole, under a
file lock that pytest-xdist workers share, so a folder that exists is
complete and pip runs once per machine.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

PIP_TIMEOUT_S = 180.0  # one pip run, download included
LOCK_WAIT_S = PIP_TIMEOUT_S + 30.0  # another worker's pip run, then ours
_LOCK_STEP_S = 0.2


def cache_root() -> Path:
    """``$XDG_CACHE_HOME/fossbot-hil-tests`` (an absolute XDG_CACHE_HOME only, as the
    XDG spec says), else ``~/.cache/fossbot-hil-tests``."""
    base = os.environ.get("XDG_CACHE_HOME", "")
    root = Path(base) if os.path.isabs(base) else Path.home() / ".cache"
    return root / "fossbot-hil-tests"


def roboticia_site() -> Path:
    """A folder holding rplidar-roboticia 0.9.5 (module ``rplidar``), for a client's
    PYTHONPATH; installed the first time it is asked for on this machine."""
    return _installed("rplidar-roboticia", "0.9.5", "rplidar_roboticia-0.9.5.dist-info")


def _installed(name: str, version: str, marker: str) -> Path:
    """`name`==`version` installed (no dependencies) in its own cache folder; `marker`
    is a path inside the folder that only a finished install has."""
    root = cache_root()
    target = root / f"{name}-{version}"
    if (target / marker).exists():
        return target
    root.mkdir(parents=True, exist_ok=True)
    with _locked(root / f".{name}-{version}.lock"):
        if (target / marker).exists():  # another worker installed it meanwhile
            return target
        scratch = Path(tempfile.mkdtemp(prefix=f".{target.name}-", dir=root))
        try:
            _pip_install(f"{name}=={version}", scratch)
            if not (scratch / marker).exists():
                pytest.fail(f"pip installed {name}=={version} without {marker}", pytrace=False)
            scratch.chmod(0o755)  # mkdtemp made it private
            shutil.rmtree(target, ignore_errors=True)  # a folder left by hand, not ours
            os.rename(scratch, target)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
    return target


@contextmanager
def _locked(path: Path) -> Iterator[None]:
    """An exclusive fcntl lock on `path`, waited for at most ``LOCK_WAIT_S``."""
    with open(path, "a") as file:  # closing it releases the lock
        deadline = time.monotonic() + LOCK_WAIT_S
        while True:
            try:
                fcntl.flock(file, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() >= deadline:
                    pytest.fail(
                        f"{path}: still locked after {LOCK_WAIT_S:g} s (another test "
                        "process installing?)",
                        pytrace=False,
                    )
                time.sleep(_LOCK_STEP_S)
        yield


def _pip_install(requirement: str, target: Path) -> None:
    """``pip install --no-deps --target`` with a bounded time; pytest.fail with
    pip's last lines if it cannot."""
    command = [
        sys.executable,
        "-m",
        "pip",
        "install",
        "--no-deps",
        "--no-input",
        "--disable-pip-version-check",
        "--target",
        str(target),
        requirement,
    ]
    try:
        done = subprocess.run(
            command, capture_output=True, text=True, timeout=PIP_TIMEOUT_S, check=False
        )
    except subprocess.TimeoutExpired as err:
        output = _text(err.stdout) + _text(err.stderr)
        pytest.fail(
            f"pip could not install {requirement} in {PIP_TIMEOUT_S:g} s:\n{_tail(output)}",
            pytrace=False,
        )
    if done.returncode != 0:
        pytest.fail(
            f"pip could not install {requirement} (exit {done.returncode}):\n"
            f"{_tail(done.stdout + done.stderr)}",
            pytrace=False,
        )


def _text(data: bytes | str | None) -> str:
    if isinstance(data, bytes):
        return data.decode(errors="replace")
    return data or ""


def _tail(output: str, lines: int = 10) -> str:
    return "\n".join(output.strip().splitlines()[-lines:])
