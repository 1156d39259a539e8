"""Whether a node command may be started by fork from the warm Python, and how (no rclpy).

A forked node must be what its command would have started: the same Python, finding
every module where a fresh interpreter would. So only a Python script is served
(``python3 node.py``, ``-u`` only, or a ``#!`` naming a Python), whose interpreter,
asked once with the node's environment, is the server's version and finds every
module the server imported in the same file (a ``yaml.py`` beside the script is seen),
and whose environment sets nothing read only at start (``PYTHON*`` but path and
buffering, ``LD_PRELOAD``, a ``LD_LIBRARY_PATH`` adding libraries). Anything else is
started as its command. The answer gives the forked node's search path, script first."""

from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from harness.nodes.setup_problems import is_python

SERVER_MODULE = "harness.nodes.warm_python"
ALLOWED_FLAGS = ("-u",)  # the server's streams are unbuffered already
# Read by the interpreter as it starts, so a forked node would not see a change.
SAME_AT_START = ("LD_PRELOAD",)
FREE_PYTHON_VARIABLES = ("PYTHONPATH", "PYTHONUNBUFFERED", "PYTHONDONTWRITEBYTECODE")
STARTUP_MODULES = ("sitecustomize", "usercustomize")
PROBE_TIMEOUT_S = 10.0
SHEBANG_BYTES = 512
FORKED = "started by fork from a warm Python (rclpy imported once; its code read afresh)"

# Run by the node's interpreter: its version, its module search path for the
# script, and which of the server's modules it would find elsewhere.
PROBE = """
import importlib.util, json, sys
asked = json.load(sys.stdin)
sys.path[0] = asked["folder"]
differ = []
for name, origin in asked["modules"].items():
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        spec = None
    found = "" if spec is None else (
        spec.origin or ":".join(spec.submodule_search_locations or ()))
    if found != origin:
        differ.append(name)
print(json.dumps({"version": sys.version, "path": sys.path, "differ": differ}))
"""


@dataclass(frozen=True)
class ScriptCommand:
    """A command that runs a Python script: which interpreter, which script, its arguments."""

    interpreter: str
    script: str  # absolute
    args: tuple[str, ...]


@dataclass(frozen=True)
class StartPlan:
    """How a node is started: by fork (`script` and `sys_path` set) or as its command."""

    how: str  # one line for the user
    script: str | None = None
    sys_path: tuple[str, ...] = ()
    args: tuple[str, ...] = ()


def script_command(argv: Sequence[str], env: Mapping[str, str]) -> ScriptCommand | str:
    """The Python script `argv` runs, or why it runs none (a reason for the user)."""
    program = _which(argv[0], env)
    if program is None:
        return f"{argv[0]} not found"
    if is_python(program):
        return _interpreter_command(program, list(argv[1:]), env)
    line = _first_line(program)
    if line is None:
        return "not a Python script (a compiled program or a shell wrapper)"
    try:
        words = shlex.split(line)
    except ValueError:
        words = []
    if words and Path(words[0]).name == "env":
        words = words[1:]
    if not words or not is_python(words[0]):
        return f"not a Python script (its #! runs {words[0] if words else 'nothing'})"
    interpreter = _which(words[0], env)
    if interpreter is None:
        return f"its interpreter {words[0]} is not found"
    return _interpreter_command(interpreter, [*words[1:], program, *argv[1:]], env)


def _interpreter_command(
    interpreter: str, args: list[str], env: Mapping[str, str]
) -> ScriptCommand | str:
    """``python [-u] SCRIPT ARGS``: the script and its arguments, or why not served."""
    while args and args[0].startswith("-"):
        if args[0] not in ALLOWED_FLAGS:
            return f"Python option {args[0]} (a fresh interpreter honours it)"
        args = args[1:]
    if not args:
        return "no script to run"
    script = os.path.abspath(args[0])
    return ScriptCommand(interpreter, script, tuple(args[1:]))


def _which(program: str, env: Mapping[str, str]) -> str | None:
    if "/" in program:
        return os.path.abspath(program) if os.path.isfile(program) else None
    return shutil.which(program, path=env.get("PATH"))


def _first_line(program: str) -> str | None:
    """The program's ``#!`` line (without the ``#!``), or None when it has none."""
    try:
        with open(program, "rb") as file:
            head = file.read(SHEBANG_BYTES)
    except OSError:
        return None
    if not head.startswith(b"#!"):
        return None
    return head[2:].split(b"\n", 1)[0].decode("utf-8", "replace").strip()


def environment_difference(env: Mapping[str, str], server_env: Mapping[str, str]) -> str | None:
    """What in the node's environment an interpreter reads only as it starts and the
    server was started without; None when nothing."""
    names = {n for n in (*env, *server_env) if n.startswith("PYTHON")} - set(FREE_PYTHON_VARIABLES)
    for name in sorted(names | set(SAME_AT_START)):
        if env.get(name) != server_env.get(name):
            return f"{name} differs from the harness's (read as an interpreter starts)"
    had = server_env.get("LD_LIBRARY_PATH", "").split(os.pathsep)
    added = [p for p in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p and p not in had]
    for folder in added:
        if any(Path(folder).glob("*.so*")):
            return f"LD_LIBRARY_PATH adds shared libraries ({folder})"
    return None


_PROBED: dict[tuple[object, ...], dict[str, object] | str] = {}


def probe(
    interpreter: str, folder: str, env: Mapping[str, str], modules: Mapping[str, str]
) -> dict[str, object] | str:
    """Ask `interpreter` (with `env`, the script in `folder`) for its version, its module
    search path and the server's modules it would find elsewhere; a reason if it cannot
    say. Asked once per interpreter, path and folder state."""
    key = (interpreter, folder, _mtime(folder), env.get("PYTHONPATH"), env.get("PATH"))
    key += tuple(_mtime(p) for p in env.get("PYTHONPATH", "").split(os.pathsep) if p)
    if key not in _PROBED:
        _PROBED[key] = _ask(interpreter, folder, env, modules)
    return _PROBED[key]


def _ask(
    interpreter: str, folder: str, env: Mapping[str, str], modules: Mapping[str, str]
) -> dict[str, object] | str:
    question = json.dumps({"folder": folder, "modules": dict(modules)})
    try:
        done = subprocess.run(
            [interpreter, "-c", PROBE],
            input=question,
            capture_output=True,
            text=True,
            env=dict(env),
            timeout=PROBE_TIMEOUT_S,
            check=False,
        )
        answer = json.loads(done.stdout)
    except (OSError, subprocess.TimeoutExpired, ValueError) as err:
        return f"could not ask {interpreter} for its modules ({type(err).__name__})"
    if done.returncode != 0 or not isinstance(answer, dict):
        return f"could not ask {interpreter} for its modules (exit code {done.returncode})"
    return answer


def _mtime(path: str) -> int:
    try:
        return os.stat(path).st_mtime_ns
    except OSError:
        return 0


def plan_start(
    argv: Sequence[str],
    env: Mapping[str, str],
    *,
    version: str,
    modules: Mapping[str, str],
    server_env: Mapping[str, str],
) -> StartPlan:
    """By fork or as a command: the plan for `argv` with `env`, given the server's Python
    `version`, its imported `modules` and the environment it was started with."""
    found = script_command(argv, env)
    if isinstance(found, str):
        return StartPlan(f"started as a command: {found}")
    different = environment_difference(env, server_env)
    if different is not None:
        return StartPlan(f"started as a command: {different}")
    folder = os.path.dirname(os.path.realpath(found.script))
    # Imported as an interpreter starts: a node whose path has one the server lacks
    # (the modem-line shim of a board command) must start as a command.
    startup = {name: modules.get(name, "") for name in STARTUP_MODULES}
    answer = probe(found.interpreter, folder, env, {**modules, **startup})
    if isinstance(answer, str):
        return StartPlan(f"started as a command: {answer}")
    if answer.get("version") != version:
        return StartPlan(f"started as a command: {found.interpreter} is another Python")
    differ = [str(name) for name in answer.get("differ", [])]  # type: ignore[union-attr]
    if differ:
        named = ", ".join(sorted(differ)[:3]) + (", ..." if len(differ) > 3 else "")
        return StartPlan(
            f"started as a command: {found.interpreter} would import {named} from "
            "elsewhere than the harness's Python"
        )
    path = tuple(str(p) for p in answer.get("path", []))  # type: ignore[union-attr]
    return StartPlan(FORKED, found.script, path, found.args)
