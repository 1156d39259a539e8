"""The layout docs/architecture.md draws: packages in layers, pure ones pure.

A package may import only from the ground and from packages on a lower
layer (imports inside functions count; those under ``TYPE_CHECKING`` do
not, they never run). Moving a module, or adding a package, means placing
it in ``LAYERS`` here and on the map in docs/architecture.md.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]  # the source tree, also where CI installs a copy
HARNESS = ROOT / "harness"
DOCS = ROOT / "docs" / "architecture.md"

# Folders of data or of the bundled nodes, not packages of the harness's code.
NOT_CODE = {"reference", "board_driver", "robot_models", "scenarios"}

# What every layer may use, at the root of the package.
GROUND = {
    "__init__",
    "errors",
    "safe_text",
    "holder_lock",
    "atomic_write",
    "user_cache",
    "text_file",
    "ctrl_c",
    "shell_words",
    "option_names",
}

# Bottom to top; a package imports only from layers below its own.
LAYERS: list[set[str]] = [
    {"lidar", "nodes", "serial_line", "cluster"},
    {"faults", "devices", "ros", "launch_files", "sandbox"},
    {"scenario", "judge"},
    {"sim", "record"},
    {"links", "report"},
    {"runner"},
    {"run_request"},
    {"bench", "grading", "live", "campaign", "hunt"},
    {"watch", "audit"},
    {"commands"},
    {"pytest_plugin", "cli"},
]
RANK = {name: rank for rank, names in enumerate(LAYERS, start=1) for name in names}

# Importing these must not import rclpy or pybullet (nor pyserial for most).
PURE = [
    "harness.lidar",
    "harness.faults",
    "harness.judge",
    "harness.scenario",
    "harness.devices",
    "harness.serial_line.stream_policy",
    "harness.serial_line.stats",
    "harness.serial_line.pacing",
    "harness.ros.domain",
    "harness.ros.names",
    "harness.ros.cdr",
    "harness.ros.shm_ports",
    "harness.launch_files",
    "harness.nodes.package_folder",
    "harness.sim.motion",
    "harness.watch.sources",
    "harness.nodes.python_script",
    "harness.nodes.colcon_hooks",
    "harness.watch.order",
    "harness.watch.verdict_cache",
    "harness.audit.mutants",
    "harness.audit.matrix",
    "harness.user_cache",
    "harness.text_file",
    "harness.shell_words",
    "harness.grading.discover",
    "harness.grading.archives",
    "harness.grading.class_table",
    "harness.grading.scoring",
    "harness.grading.grading_file",
    "harness.grading.roster",
    "harness.grading.hidden",
    "harness.grading.gradescope",
    "harness.grading.gradebook",
    "harness.grading.student_text",
    "harness.sandbox.bwrap",
    "harness.sandbox.limits",
    "harness.sandbox.refusals",
    "harness.hunt.space",
    "harness.hunt.shrink",
    "harness.hunt.margin",
    "harness.run_request",
]


def _unit(module: str) -> str:
    """The package (or root module) a dotted module name belongs to; a name taken
    from ``harness`` itself (``lazy_exports``, ``__version__``) is the root's."""
    parts = module.split(".")
    if len(parts) < 2:
        return "__init__"
    is_code = (HARNESS / parts[1]).is_dir() or (HARNESS / f"{parts[1]}.py").is_file()
    return parts[1] if is_code else "__init__"


def _code_files() -> list[Path]:
    return [
        path
        for path in sorted(HARNESS.rglob("*.py"))
        if not NOT_CODE & set(path.relative_to(HARNESS).parts)
    ]


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every harness import that can run, wherever it stands."""
    tree = ast.parse(path.read_text(), filename=str(path))
    typing_only = {
        id(inner)
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for inner in ast.walk(node)
    }
    found = []
    for node in ast.walk(tree):
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if node.module == "harness":
                found += [(node.lineno, f"harness.{alias.name}") for alias in node.names]
            elif node.module.startswith("harness."):
                found.append((node.lineno, node.module))
        elif isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names if a.name.startswith("harness.")]
    return found


def _source_unit(path: Path) -> str:
    relative = path.relative_to(HARNESS)
    return relative.parts[0] if len(relative.parts) > 1 else relative.stem


def test_every_package_and_root_module_has_a_place() -> None:
    units = {_source_unit(path) for path in _code_files()}
    unplaced = sorted(units - GROUND - set(RANK))
    assert not unplaced, f"place these in LAYERS (and docs/architecture.md): {unplaced}"
    gone = sorted(set(RANK) - units)
    assert not gone, f"LAYERS names what no longer exists: {gone}"


def test_packages_import_only_from_lower_layers() -> None:
    upward = []
    for path in _code_files():
        source = _source_unit(path)
        for line, module in _imports(path):
            target = _unit(module)
            if target == source or target in GROUND:
                continue
            if source in GROUND:
                upward.append(f"{path.relative_to(HARNESS)}:{line}: the ground imports {module}")
            elif RANK.get(target, 0) >= RANK[source]:
                upward.append(f"{path.relative_to(HARNESS)}:{line}: {source} imports {module}")
    assert not upward, "imports that run sideways or back up:\n" + "\n".join(upward)


def test_pure_packages_import_neither_rclpy_nor_pybullet() -> None:
    modules = []
    for name in PURE:
        folder = HARNESS.joinpath(*name.split(".")[1:])
        if folder.is_dir():
            inside = sorted(p.stem for p in folder.glob("*.py") if p.stem != "__init__")
            modules += [f"{name}.{stem}" for stem in inside]
        modules.append(name)
    code = (
        "import importlib, sys\n"
        f"for name in {modules!r}: importlib.import_module(name)\n"
        "print(' '.join(m for m in ('rclpy', 'pybullet') if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "", f"pure modules pulled in: {done.stdout.strip()}"


def test_every_package_says_what_it_is_for() -> None:
    silent = [
        str(path.relative_to(HARNESS))
        for path in _code_files()
        if path.name == "__init__.py" and not ast.get_docstring(ast.parse(path.read_text()))
    ]
    assert not silent, f"packages without a docstring: {silent}"


def test_the_map_names_every_package() -> None:
    text = DOCS.read_text()
    missing = sorted(name for name in RANK if name != "cli" and f"{name}/" not in text)
    assert not missing, f"docs/architecture.md does not show: {missing}"


MAX_MODULE_LINES = 600  # a module past this holds more than one concept: split it by role


def test_no_module_is_over_600_lines() -> None:
    long = sorted(
        f"{path.relative_to(HARNESS)} ({count})"
        for path in _code_files()
        if (count := len(path.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES
    )
    assert not long, f"modules over {MAX_MODULE_LINES} lines: {long}"
