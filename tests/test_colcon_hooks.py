"""The environment a colcon workspace's hook files give, as sourcing setup.bash would."""

from __future__ import annotations

from pathlib import Path

from harness.nodes.colcon_hooks import colcon_packages, hook_environment


def package(prefix: Path, name: str, lines: list[str]) -> None:
    """A package installed by colcon into `prefix`, its package.dsv holding `lines`."""
    (prefix / "share/colcon-core/packages").mkdir(parents=True, exist_ok=True)
    (prefix / "share/colcon-core/packages" / name).write_text("")
    share = prefix / "share" / name
    (share / "hook").mkdir(parents=True, exist_ok=True)
    (share / "package.dsv").write_text("\n".join(lines) + "\n")


def test_a_symlink_install_puts_its_build_folder_on_the_path(tmp_path: Path) -> None:
    prefix = tmp_path / "install/pkg"
    build = tmp_path / "build/pkg"
    package(
        prefix,
        "pkg",
        [
            "source;share/pkg/hook/pythonpath.dsv",
            "source;share/pkg/hook/pythonpath.sh",  # a shell's hook: not read
            "source;share/pkg/hook/ament_prefix_path.dsv",
            f"source;{build}/share/pkg/hook/pythonpath_develop.dsv",
        ],
    )
    hook = prefix / "share/pkg/hook"
    (hook / "pythonpath.dsv").write_text(
        "prepend-non-duplicate;PYTHONPATH;lib/python3.11/site-packages\n"
    )
    (hook / "ament_prefix_path.dsv").write_text("prepend-non-duplicate;AMENT_PREFIX_PATH;\n")
    (build / "share/pkg/hook").mkdir(parents=True)
    (build / "share/pkg/hook/pythonpath_develop.dsv").write_text(
        f"prepend-non-duplicate;PYTHONPATH;{build}\n"
    )
    env = hook_environment([prefix], {"PYTHONPATH": "/old", "HOME": "/h"})
    assert env == {
        "PYTHONPATH": f"{build}:{prefix}/lib/python3.11/site-packages:/old",
        "AMENT_PREFIX_PATH": str(prefix),
    }
    assert colcon_packages(prefix) == ["pkg"]


def test_set_append_and_missing_paths(tmp_path: Path) -> None:
    prefix = tmp_path / "p"
    package(
        prefix,
        "a",
        [
            "set;MODE;on",
            "set-if-unset;KEPT;new",
            "append-non-duplicate;PATH;bin",
            "prepend-non-duplicate-if-exists;LD_LIBRARY_PATH;lib",
            "source;share/a/hook/loop.dsv",
        ],
    )
    (prefix / "share/a/hook/loop.dsv").write_text("source;share/a/hook/loop.dsv\n")
    env = hook_environment([prefix], {"KEPT": "old", "PATH": "/usr/bin"})
    assert env == {"MODE": "on", "PATH": f"/usr/bin:{prefix}/bin"}  # no lib/: not added


def test_the_first_workspace_comes_first(tmp_path: Path) -> None:
    first, second = tmp_path / "one", tmp_path / "two"
    for prefix in (first, second):
        package(prefix, prefix.name, ["prepend-non-duplicate;AMENT_PREFIX_PATH;"])
    env = hook_environment([first, second], {})
    assert env["AMENT_PREFIX_PATH"] == f"{first}:{second}"


def test_a_prefix_without_colcon_adds_nothing(tmp_path: Path) -> None:
    assert hook_environment([tmp_path], {"A": "1"}) == {}
