"""colcon on node/, the way a lab workspace builds it: one package into a temporary workspace.

colcon (colcon-common-extensions, with colcon-ros for ament_python packages)
comes with the project's `test` extra, so it is imported plainly here: where
it is missing, the build tests fail loudly instead of skipping.
"""

from __future__ import annotations

import shutil
import subprocess
import sysconfig
from pathlib import Path

import colcon_core  # noqa: F401  (the `colcon` command below)
import colcon_ros  # noqa: F401  (colcon's build and test of ament_python packages)

REPO = Path(__file__).resolve().parents[1]


def colcon(
    *args: str, package: str, base: Path, timeout: float
) -> subprocess.CompletedProcess[str]:
    """Run colcon on the node/ folder's `package` only, with every output under `base`."""
    command = [
        shutil.which("colcon") or "colcon",
        "--log-base",
        str(base / "log"),
        *args,
        "--base-paths",
        "node",
        "--packages-select",
        package,
        "--build-base",
        str(base / "build"),
        "--install-base",
        str(base / "install"),
    ]
    return subprocess.run(
        command, cwd=REPO, capture_output=True, text=True, timeout=timeout, check=False
    )


def colcon_build(package: str, base: Path, *, timeout: float) -> Path:
    """`colcon build` of `package` into the workspace `base`; returns its install prefix."""
    result = colcon("build", package=package, base=base, timeout=timeout)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return base / "install" / package


def colcon_test(package: str, prefix: Path, *, timeout: float) -> None:
    """`colcon test` of the package installed at `prefix`, then `colcon test-result`: clean."""
    base = prefix.parent.parent
    results = base / "test_results"
    tested = colcon(
        "test", "--test-result-base", str(results), package=package, base=base, timeout=timeout
    )
    assert tested.returncode == 0, tested.stdout[-3000:] + tested.stderr[-3000:]
    summary = subprocess.run(
        [shutil.which("colcon") or "colcon", "test-result", "--test-result-base", str(results)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert summary.returncode == 0, summary.stdout + summary.stderr
    assert "0 failures" in summary.stdout and "0 errors" in summary.stdout


def site_packages(prefix: Path) -> Path:
    """The install's site-packages, which colcon's setup scripts put on PYTHONPATH."""
    relative = Path(sysconfig.get_path("purelib")).relative_to(sysconfig.get_path("data"))
    return prefix / relative


def build_leftovers(package: str) -> list[str]:
    """Egg-info or build output that a build left next to the package's sources."""
    package_dir = REPO / "node" / package
    return [
        p.name
        for p in package_dir.iterdir()
        if p.name.endswith(".egg-info") or p.name in ("build", "install", "log")
    ]
