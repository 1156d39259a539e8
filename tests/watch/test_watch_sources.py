"""What `run --watch` watches for a node, and when a change needs a colcon build.

Real files in a temporary folder; the colcon layouts are the files colcon
leaves (an .egg-link, symlinks in build/), checked against a real build in
test_watch_workspace.py.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from harness.cli import build_parser, flag_names
from harness.errors import ConfigError
from harness.links.base import LinkOptions
from harness.option_names import speaking
from harness.watch.sources import (
    Build,
    find_package,
    node_sources,
    package_file,
    scenario_sources,
    symlink_installed,
)

PACKAGE_XML = "<package format='3'><name>{name}</name></package>"


def script(folder: Path, name: str = "node.py") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text("print('node')\n")
    return path.resolve()


def sources_of(**options: object):
    return node_sources("ros2", LinkOptions(**options))


@pytest.mark.parametrize(
    "command", ["python3 {s} --flag", "{s}", f"{sys.executable} -u {{s}}", "python3 -W error {s}"]
)
def test_a_script_and_the_python_files_beside_it(tmp_path: Path, command: str) -> None:
    """A Python script: its folder's .py files count, nothing else and nothing deeper."""
    node = script(tmp_path / "lab")
    sources = sources_of(node=command.format(s=node))
    assert sources.build is None
    folder = node.parent
    assert sources.matches(node) and sources.matches(folder / "helpers.py")
    assert not sources.matches(folder / "notes.txt")
    assert not sources.matches(folder / "sub" / "deep.py")  # one level: a home folder is cheap
    assert not sources.matches(folder / ".#node.py")  # an editor's lock file
    assert not sources.matches(folder / "node.py~")
    assert not sources.matches(tmp_path / "elsewhere.py")
    assert [w.recursive for w in sources.watched] == [False]
    assert "node.py" in sources.description[0]


def test_another_program_that_is_a_file(tmp_path: Path) -> None:
    """A program given by its path (a shell script): that file alone."""
    program = tmp_path / "start_node.sh"
    program.write_text("#!/bin/sh\n")
    sources = sources_of(node=f"{program} --fast")
    assert sources.matches(program.resolve())
    assert not sources.matches((tmp_path / "other.sh").resolve())


@pytest.mark.parametrize(
    ("command", "message"),
    [
        ("python3 missing.py", "no such script missing.py"),
        ("python3 -m my_package.node", "cannot tell which files"),
        ("python3 -c 'import x'", "cannot tell which files"),
        ("ros2 run my_package my_node", "is a program, not a file of yours"),
        ("python3 'unclosed", "No closing quotation"),
    ],
)
def test_a_command_whose_files_cannot_be_found(command: str, message: str) -> None:
    """Nothing to watch in the command line: a usage error that says why."""
    with pytest.raises(ConfigError, match=message):
        sources_of(node=command)


def test_the_bundled_node_brings_nothing() -> None:
    """The reference node and the reference function are not the user's to edit."""
    assert not sources_of().watched
    assert not node_sources("inprocess", LinkOptions()).watched
    assert not node_sources("inprocess", LinkOptions(processor="my_module:process")).watched


def test_a_processor_file(tmp_path: Path) -> None:
    """--processor FILE.py:FUNCTION: that file (it is loaded anew for each scenario)."""
    path = script(tmp_path, "proc.py")
    sources = node_sources("inprocess", LinkOptions(processor=f"{path}:process"))
    assert sources.matches(path) and not sources.matches(path.parent / "helper.py")
    with pytest.raises(ConfigError, match="no such file"):
        node_sources("inprocess", LinkOptions(processor=f"{tmp_path}/gone.py:process"))


def make_workspace(root: Path, name: str = "my_pkg", *, inside: str = "src/my_pkg") -> Path:
    """A workspace with one package's sources, built once (an install/ folder)."""
    package = root / inside
    (package / name).mkdir(parents=True)
    (package / "package.xml").write_text(PACKAGE_XML.format(name=name))
    (package / "setup.py").write_text("")
    (package / name / "node.py").write_text("")
    (root / "install").mkdir()
    return package


def test_a_workspace_package_is_found_as_colcon_finds_it(tmp_path: Path) -> None:
    """The package.xml naming the package, not the copies colcon put in build/ or install/,
    nor one in a folder colcon ignores."""
    ws = tmp_path / "ws"
    for decoy in ("build/my_pkg", "install/my_pkg/share/my_pkg", "log/x", "ignored/my_pkg"):
        (ws / decoy).mkdir(parents=True)
        (ws / decoy / "package.xml").write_text(PACKAGE_XML.format(name="my_pkg"))
    (ws / "ignored" / "COLCON_IGNORE").write_text("")
    (ws / "src" / "other").mkdir(parents=True)
    (ws / "src" / "other" / "package.xml").write_text(PACKAGE_XML.format(name="other"))
    (ws / "src" / "broken").mkdir()
    (ws / "src" / "broken" / "package.xml").write_text("<package")
    package = ws / "src" / "deep" / "my_pkg"
    package.mkdir(parents=True)
    (package / "package.xml").write_text(PACKAGE_XML.format(name="my_pkg"))
    assert find_package(ws, "my_pkg") == package
    assert find_package(ws, "nothing") is None


def test_sources_through_a_symlinked_folder(tmp_path: Path) -> None:
    """src/ may be a symlink to the sources (followed), and the watcher sees real paths."""
    real = make_workspace(tmp_path / "elsewhere", inside="my_pkg")
    ws = tmp_path / "ws"
    (ws / "install").mkdir(parents=True)
    (ws / "src").symlink_to(real.parent)
    sources = sources_of(workspace=str(ws), package="my_pkg", executable="node")
    assert sources.build is not None and sources.build.source == real.resolve()
    assert sources.matches(real.resolve() / "my_pkg" / "node.py")


def test_the_package_files_that_count() -> None:
    """Python files, setup.py, setup.cfg, package.xml, resource/; not what builds leave."""
    counted = ["setup.py", "setup.cfg", "package.xml", "resource/my_pkg", "my_pkg/node.py", "a.py"]
    ignored = ["README.md", "my_pkg/__pycache__/node.py", "my_pkg.egg-info/x.py", "build/x.py"]
    assert all(package_file(Path(p)) for p in counted)
    assert not any(package_file(Path(p)) for p in ignored)


def test_a_plain_build_rebuilds_on_every_change(tmp_path: Path) -> None:
    """Without --symlink-install the install holds copies: any change needs a build."""
    package = make_workspace(tmp_path).resolve()
    sources = sources_of(workspace=str(tmp_path), package="my_pkg", executable="node")
    build = sources.build
    assert build is not None and not build.symlink_install and not build.merge_install
    assert build.needed([package / "my_pkg" / "node.py"])
    assert not build.needed([package / "README.md"])
    assert not build.needed([tmp_path / "elsewhere.py"])
    assert build.command("colcon") == ["colcon", "build", "--packages-select", "my_pkg"]
    assert sources.watched[0].recursive


@pytest.mark.parametrize("marker", ["egg-link", "build symlink"])
def test_a_symlink_install_needs_a_build_only_for_its_setup(tmp_path: Path, marker: str) -> None:
    """With --symlink-install a .py runs where it is; setup files still need colcon."""
    package = make_workspace(tmp_path).resolve()
    if marker == "egg-link":
        site = tmp_path / "install/my_pkg/lib/python3.11/site-packages"
        site.mkdir(parents=True)
        (site / "my-pkg.egg-link").write_text(str(package))
    else:
        (tmp_path / "build" / "my_pkg").mkdir(parents=True)
        (tmp_path / "build" / "my_pkg" / "my_pkg").symlink_to(package / "my_pkg")
    assert symlink_installed(tmp_path, "my_pkg")
    build = sources_of(workspace=str(tmp_path), package="my_pkg", executable="node").build
    assert build is not None and build.symlink_install
    assert not build.needed([package / "my_pkg" / "node.py"])
    for name in ("setup.py", "setup.cfg", "package.xml", "resource/my_pkg"):
        assert build.needed([package / name]), name
    assert "--symlink-install" in build.command("colcon")


def test_a_merged_install_is_rebuilt_merged(tmp_path: Path) -> None:
    """colcon refuses to switch layouts: --merge-install when the workspace has one."""
    make_workspace(tmp_path)
    (tmp_path / "install/share/ament_index/resource_index/packages").mkdir(parents=True)
    build = sources_of(workspace=str(tmp_path), package="my_pkg", executable="node").build
    assert build == Build(build.workspace, "my_pkg", build.source, False, True)
    assert build.command("colcon")[-1] == "--merge-install"


@pytest.mark.parametrize(
    ("layout", "options", "message"),
    [
        ("no install", {"workspace": "WS", "package": "my_pkg"}, "has no install/ folder"),
        ("built", {"workspace": "WS", "package": "other_pkg"}, "no package.xml naming other_pkg"),
        ("built", {"package": "my_pkg"}, "needs --workspace DIR"),
    ],
)
def test_a_workspace_without_the_sources(
    tmp_path: Path, layout: str, options: dict[str, str], message: str
) -> None:
    """An install folder alone, or no package of that name: nothing to watch or build."""
    make_workspace(tmp_path)
    if layout == "no install":
        (tmp_path / "install").rmdir()
    given = {k: (str(tmp_path) if v == "WS" else v) for k, v in options.items()}
    with speaking(flag_names(build_parser())), pytest.raises(ConfigError, match=message):
        sources_of(executable="node", **given)


def test_scenario_files_given_by_path(tmp_path: Path) -> None:
    """Scenario files named by path are watched; shipped names are not."""
    scenario = tmp_path / "mine.yaml"
    scenario.write_text("name: mine\n")
    sources = scenario_sources([str(scenario), "approach_wall"])
    assert sources.scenario_files == {scenario.resolve()}
    assert sources.matches(scenario.resolve())
    assert not sources.matches(tmp_path / "other.yaml")
    both = sources_of(node=f"python3 {script(tmp_path)}").plus(sources)
    assert both.matches(scenario.resolve()) and both.matches(tmp_path.resolve() / "node.py")
