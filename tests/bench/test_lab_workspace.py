"""The suite stage's workspace node and commands: why a figure cannot be measured, in one line.

The successful build and runs are the quick bench's (tests/test_bench.py);
here the ways they fail, each named in the bench's `errors` instead of a
figure measured on something else.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from harness.bench.lab_workspace import (
    LAB_PACKAGE,
    build_lab_workspace,
    colcon_program,
    lab_package_source,
)
from harness.bench.suite_commands import cli_wall_s
from harness.errors import HarnessError

REPO = Path(__file__).resolve().parents[2]


def test_the_lab_package_is_found_in_the_checkout(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(REPO)  # an installed wheel run in the checkout (as CI runs it)
    installed = tmp_path / "site-packages" / "harness"
    assert lab_package_source(installed).resolve() == REPO / "node" / LAB_PACKAGE
    editable = REPO / "harness"  # an editable install, run anywhere
    monkeypatch.chdir(tmp_path)
    assert lab_package_source(editable) == REPO / "node" / LAB_PACKAGE


def test_a_harness_without_its_repository_is_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    installed = tmp_path / "site-packages" / "harness"  # a wheel: no node/ beside it
    installed.mkdir(parents=True)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(HarnessError, match="installed without its repository"):
        lab_package_source(installed)


def test_missing_colcon_names_the_extra(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "executable", str(tmp_path / "python"))  # no colcon beside it
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(HarnessError, match=r"colcon not found.*\[test\].*colcon-common-extensions"):
        colcon_program()


@pytest.mark.timeout(90)
def test_a_package_that_does_not_build_is_named(tmp_path: Path) -> None:
    broken = tmp_path / "source" / LAB_PACKAGE
    broken.mkdir(parents=True)
    source = REPO / "node" / LAB_PACKAGE
    (broken / "package.xml").write_text((source / "package.xml").read_text())
    (broken / "setup.py").write_text("from setuptools import setup\nsetup(name=\n")
    workspace = tmp_path / "ws"
    workspace.mkdir()
    with pytest.raises(HarnessError, match=f"colcon build of {LAB_PACKAGE} failed: .*SyntaxError"):
        build_lab_workspace(workspace, broken, colcon_program(), timeout=60)


def test_a_run_that_does_not_pass_is_named() -> None:
    with pytest.raises(HarnessError, match="fossbot-hil run no_such_scenario exited 2: "):
        cli_wall_s(["no_such_scenario"])
