"""CLI flags spelled below commands/ (issue 40: lower layers speak of option keys; the
caller names them, as a flag, a ``--hil-*`` option or ini key, or a grading-file field).

Like tests/test_link_kinds.py for link names, the source is read, not run: every flag
the ``fossbot-hil`` parser defines, written in a string (docstrings aside) in harness/
outside commands/, cli.py, the plugin and the run request's table (a parser's own
add_argument calls aside) is counted. The counts may only go down; the issue's target is
at most five.
"""

from __future__ import annotations

import argparse
import ast
import re
from collections import Counter
from pathlib import Path

from harness.cli import build_parser

HARNESS = Path(__file__).resolve().parents[1] / "harness"
CALLERS = {"commands", "cli.py", "pytest_plugin", "run_request"}  # they name the options
NOT_CODE = {"reference", "board_driver", "robot_models", "scenarios"}
#: The lower layers the issue counted "about 70" in.
LOWER = ("links", "nodes", "launch_files", "serial_line", "ros")
MAX_LOWER = 0  # 2026-12-02: links, nodes, launch_files, serial_line and ros name options by key
MAX_BELOW_COMMANDS = 3  # bench.suite_commands.COMMAND_FLAGS: the bench runs `run` and `grade`
TARGET = 5


def _flags() -> set[str]:
    found: set[str] = set()

    def walk(parser: argparse.ArgumentParser) -> None:
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub in action.choices.values():
                    walk(sub)
            found.update(s for s in action.option_strings if s.startswith("--"))

    walk(build_parser())
    return found - {"--help", "--version"}


def _strings(tree: ast.Module) -> list[str]:
    """Every string constant of `tree` but the docstrings (f-strings' parts included)."""
    docs = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    # A program's own parser (grading/autograder.py's) defines its flags: not the CLI's.
    own = {
        id(arg)
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr == "add_argument"
        for arg in node.args
    }
    return [
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docs | own
    ]


def flag_counts() -> Counter[str]:
    """How many flag strings each top-level package (or root module) below commands/ has."""
    flags = sorted(_flags(), key=len, reverse=True)
    pattern = re.compile(r"(?<![\w-])(" + "|".join(map(re.escape, flags)) + r")(?![\w-])")
    counts: Counter[str] = Counter()
    for path in sorted(HARNESS.rglob("*.py")):
        parts = path.relative_to(HARNESS).parts
        if parts[0] in CALLERS or NOT_CODE & set(parts):
            continue
        for text in _strings(ast.parse(path.read_text(), filename=str(path))):
            counts[parts[0]] += len(pattern.findall(text))
    return counts


def test_flag_strings_below_commands_only_go_down() -> None:
    counts = flag_counts()
    lower = sum(counts[name] for name in LOWER)
    assert lower <= MAX_LOWER, f"CLI flags in {', '.join(LOWER)}: {lower} (target {TARGET})"
    total = sum(counts.values())
    assert total <= MAX_BELOW_COMMANDS, f"CLI flags below commands/: {counts.most_common()}"


def test_the_parser_defines_the_flags_counted() -> None:
    """The count follows the parser: the run request's flags are among them."""
    assert {"--port", "--board-command", "--warning-topic", "--launch"} <= _flags()
