"""The audit's library of mutants: the catalogue, the node that makes each mistake, and
that node run over a real ROS 2 graph (the control passes; an unknown name says why)."""

from __future__ import annotations

import ast
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from short_scenarios import WALL_AHEAD

from harness.audit import MUTANTS, Mutant, mutant_command, mutant_named
from harness.audit.mutants import CONTROL, NODE_SCRIPT
from harness.errors import ConfigError

SNAKE_CASE = re.compile(r"[a-z][a-z0-9]*(_[a-z0-9]+)*")
# What a student's node may import (it runs as one, not as part of the harness).
NODE_IMPORTS = {"math", "sys", "time", "numpy", "rclpy", "sensor_msgs", "std_msgs"}


def _node_tree() -> ast.Module:
    return ast.parse(NODE_SCRIPT.read_text(), filename=str(NODE_SCRIPT))


def _node_constant(name: str) -> object:
    """A module-level constant of mutant_node.py, read without importing it (no rclpy)."""
    for statement in _node_tree().body:
        if isinstance(statement, ast.Assign) and any(
            isinstance(target, ast.Name) and target.id == name for target in statement.targets
        ):
            return ast.literal_eval(statement.value)
    raise AssertionError(f"mutant_node.py defines no {name}")


def _mistakes_tested() -> set[str]:
    """Every name the node compares `self.mistake` with: the mistakes it makes."""
    found = set()
    for node in ast.walk(_node_tree()):
        if isinstance(node, ast.Compare) and ast.unparse(node.left) == "self.mistake":
            found |= {c.value for c in node.comparators if isinstance(c, ast.Constant)}
    return found


# -- the catalogue (pure) ----------------------------------------------------


def test_the_catalogue_names_at_least_22_mistakes_once_each_in_snake_case() -> None:
    names = [mutant.name for mutant in MUTANTS]
    assert len(names) >= 22
    assert len(set(names)) == len(names), "a name is used twice"
    assert all(SNAKE_CASE.fullmatch(name) for name in names), names
    assert CONTROL not in names  # the control makes no mistake


def test_each_mutant_says_its_mistake_and_what_catches_it_in_one_line() -> None:
    for mutant in MUTANTS:
        assert isinstance(mutant, Mutant)
        for text in (mutant.mistake, mutant.caught_by):
            assert text.strip() and "\n" not in text and len(text) <= 100, (mutant.name, text)


def test_the_node_makes_exactly_the_catalogued_mistakes_in_the_same_order() -> None:
    names = tuple(mutant.name for mutant in MUTANTS)
    assert _node_constant("MUTANT_NAMES") == names
    assert _node_constant("CONTROL") == CONTROL
    # Each name is a deviation somewhere in the node, and no deviation is uncatalogued.
    assert _mistakes_tested() == set(names)


def test_the_node_imports_only_what_a_student_node_may() -> None:
    imported = set()
    for node in ast.walk(_node_tree()):
        if isinstance(node, ast.Import):
            imported |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            imported.add((node.module or "").split(".")[0])
    assert imported <= NODE_IMPORTS, imported - NODE_IMPORTS


def test_the_node_is_a_script_in_the_package() -> None:
    """A script run with the harness's Python (an installed wheel keeps no execute bit)."""
    assert NODE_SCRIPT.name == "mutant_node.py" and NODE_SCRIPT.parent.name == "audit"
    assert NODE_SCRIPT.read_text().startswith("#!/usr/bin/env python3\n")
    assert shlex.split(mutant_command("correct"))[0] == sys.executable
    body = _node_tree().body
    starts = [s for s in body if isinstance(s, ast.If) and "__main__" in ast.unparse(s.test)]
    assert starts and starts[-1] is body[-1]  # importing it starts nothing


def test_an_unknown_name_is_a_config_error_naming_the_known_ones() -> None:
    with pytest.raises(ConfigError) as caught:
        mutant_named("angle_in_radians")
    message = str(caught.value)
    assert "\n" not in message and "unknown mutant 'angle_in_radians'" in message
    assert all(mutant.name in message for mutant in MUTANTS)
    with pytest.raises(ConfigError, match="the control, not a mutant"):
        mutant_named(CONTROL)
    assert mutant_named("nan_not_filtered").name == "nan_not_filtered"


def test_mutant_command_runs_the_node_script_with_the_name_quoted() -> None:
    python = "/opt/my python/bin/python3"
    command = mutant_command("warning_latched", python)
    assert shlex.split(command) == [python, str(NODE_SCRIPT), "warning_latched"]
    assert command.startswith("'/opt/my python/bin/python3' ")
    assert shlex.split(mutant_command(CONTROL)) == [sys.executable, str(NODE_SCRIPT), CONTROL]
    with pytest.raises(ConfigError, match="unknown mutant 'nope'"):
        mutant_command("nope")


# -- the node over ROS 2 -----------------------------------------------------


@pytest.mark.ros
@pytest.mark.timeout(60)
def test_an_unknown_name_exits_2_with_one_line_naming_the_known_ones() -> None:
    done = subprocess.run(
        [sys.executable, str(NODE_SCRIPT), "nope", "--ros-args", "-p", "threshold:=0.4"],
        capture_output=True,
        text=True,
        timeout=30,
        check=False,
    )
    assert done.returncode == 2 and done.stdout == ""
    [line] = done.stderr.splitlines()
    assert "unknown mutant 'nope'" in line and CONTROL in line
    assert all(mutant.name in line for mutant in MUTANTS)


@pytest.mark.ros
@pytest.mark.timeout(60)
def test_the_node_imports_as_a_module_without_starting() -> None:
    from harness.audit import mutant_node

    assert mutant_node.MUTANT_NAMES == tuple(mutant.name for mutant in MUTANTS)
    assert callable(mutant_node.main) and issubclass(mutant_node.LidarNode, object)


@pytest.mark.ros
@pytest.mark.timeout(180)
def test_the_control_passes_the_default_suite_started_by_fork() -> None:
    """`correct` is a right node: every shipped scenario passes, each node forked warm."""
    from harness.links.base import LinkOptions
    from harness.nodes.python_script import FORKED
    from harness.runner.suite import run_suite
    from harness.scenario.files import shipped_scenarios

    results = run_suite(shipped_scenarios(), "ros2", LinkOptions(node=mutant_command(CONTROL)))
    assert len(results) >= 7
    assert all(r.ok for r in results), [r.first_failure for r in results if not r.ok]
    assert all(FORKED in r.node_start for r in results), {r.node_start for r in results}


@pytest.mark.ros
@pytest.mark.timeout(120)
def test_an_unknown_mutant_never_starts_and_the_result_says_why() -> None:
    from harness.links.base import LinkOptions
    from harness.runner.suite import run_suite
    from harness.scenario.files import resolve_scenario

    command = shlex.join([sys.executable, str(NODE_SCRIPT), "no_such_mistake"])
    [result] = run_suite([resolve_scenario("approach_wall")], "ros2", LinkOptions(node=command))
    assert result.not_started and not result.ok
    said = f"{result.error}\n{result.diagnostics}"
    assert "exited with code 2" in said, said
    assert "unknown mutant 'no_such_mistake'" in said, said


@pytest.mark.ros
@pytest.mark.timeout(120)
@pytest.mark.parametrize(("name", "passes"), [(CONTROL, True), ("nan_not_filtered", False)])
def test_a_nan_beside_valid_returns_kills_nan_not_filtered(
    name: str, passes: bool, tmp_path: Path
) -> None:
    """NaN dropouts on a wall in range: only the node that lets NaN through fails."""
    from harness.links.base import LinkOptions
    from harness.runner.settings import RunSettings
    from harness.runner.suite import run_suite
    from harness.scenario.files import resolve_scenario

    scenario = tmp_path / "wall_ahead.yaml"
    scenario.write_text(WALL_AHEAD)
    [result] = run_suite(
        [resolve_scenario(str(scenario))],
        "ros2",
        LinkOptions(node=mutant_command(name)),
        RunSettings(faults=["dropouts_nan"]),
    )
    assert result.ok == passes, result.first_failure
    if not passes:
        assert "gives nan m" in (result.first_failure or ""), result.first_failure
