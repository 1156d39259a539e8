"""Reading a Python launch file from its syntax tree (``ast``): the file is never run.

Each ``launch_ros.actions.Node`` (or ``LifecycleNode``) call, however imported, with
its plain-text package, executable and name and its ``parameters=`` keys (nested
dicts dotted, as launch_ros flattens them; a name assigned a literal once is
followed). What the file decides only when run is said as such, not guessed."""

from __future__ import annotations

import ast
from pathlib import Path

from harness.launch_files.entries import LaunchFile, NodeEntry, ParamSetting, Unread

__all__ = ["read_python"]

NODE_CALLS = frozenset(
    {
        "launch_ros.actions.Node",
        "launch_ros.actions.node.Node",
        "launch_ros.actions.LifecycleNode",
        "launch_ros.actions.lifecycle_node.LifecycleNode",
    }
)
ARGUMENT_CALLS = frozenset(
    {
        "launch.actions.DeclareLaunchArgument",
        "launch.actions.declare_launch_argument.DeclareLaunchArgument",
    }
)
# Keyword names, newest first (Dashing's launch_ros said node_executable, node_name).
KEYWORDS = {"executable": ("executable", "node_executable"), "name": ("name", "node_name")}
STAR_NAMES = {  # `from launch_ros.actions import *` and `from launch.actions import *`
    "launch_ros.actions": ("Node", "LifecycleNode"),
    "launch.actions": ("DeclareLaunchArgument",),
}
FOLLOW_DEPTH = 8  # names holding names holding literals, at most this deep
SNIPPET = 60  # characters of an expression quoted in a note
MUTATORS = frozenset({"update", "append", "extend", "insert", "setdefault", "pop", "clear"})


def read_python(text: str, path: Path, shown: str) -> LaunchFile | None:
    """The launch file's nodes and arguments; None when it is no launch file (it
    defines no ``generate_launch_description``)."""
    try:
        tree = ast.parse(text, filename=shown)
    except SyntaxError as err:
        return LaunchFile(
            path, shown, unread=(Unread(err.lineno or 1, f"does not parse as Python: {err.msg}"),)
        )
    except ValueError as err:  # a null byte
        return LaunchFile(path, shown, unread=(Unread(1, f"does not parse as Python: {err}"),))
    defines = any(
        isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)
        and n.name == "generate_launch_description"
        for n in ast.walk(tree)
    )
    if not defines:
        return None
    return _Reader(tree, text).read(path, shown)


class _Reader:
    """One file's imports and single assignments, then its Node and argument calls."""

    def __init__(self, tree: ast.Module, text: str) -> None:
        self.tree, self.text = tree, text
        self.imports = _imports(tree)
        self.values = _single_assignments(tree)
        self.unread: list[Unread] = []

    def read(self, path: Path, shown: str) -> LaunchFile:
        nodes, arguments = [], []
        for call in (n for n in ast.walk(self.tree) if isinstance(n, ast.Call)):
            called = self._qualified(call.func)
            if called in NODE_CALLS:
                nodes.append(self._node(call))
            elif called in ARGUMENT_CALLS:
                name = self._argument_name(call)
                if name is not None:
                    arguments.append(name)
        nodes.sort(key=lambda n: n.line)
        self.unread.sort(key=lambda u: u.line)
        return LaunchFile(path, shown, tuple(nodes), tuple(arguments), tuple(self.unread))

    # -- names ---------------------------------------------------------------
    def _qualified(self, func: ast.expr) -> str | None:
        """`Node`, `actions.Node` or `launch_ros.actions.Node` as its module path."""
        parts: list[str] = []
        while isinstance(func, ast.Attribute):
            parts.append(func.attr)
            func = func.value
        if not isinstance(func, ast.Name) or func.id not in self.imports:
            return None
        return ".".join([self.imports[func.id], *reversed(parts)])

    def _follow(self, expr: ast.expr) -> ast.expr:
        """The literal a name holds (assigned once, never changed), else `expr`."""
        for _ in range(FOLLOW_DEPTH):
            if not isinstance(expr, ast.Name) or expr.id not in self.values:
                return expr
            expr = self.values[expr.id]
        return expr

    def _snippet(self, expr: ast.expr) -> str:
        text = ast.get_source_segment(self.text, expr) or ast.unparse(expr)
        text = " ".join(text.split())
        return text if len(text) <= SNIPPET else text[: SNIPPET - 3] + "..."

    def _runtime(
        self, expr: ast.expr, what: str, then: str = "not checked", verb: str = "is"
    ) -> None:
        """Say that `what` (its ``{}`` the expression's text) is known only when the file runs."""
        text = f"{what.format(self._snippet(expr))} {verb} known only when the file runs: {then}"
        self.unread.append(Unread(expr.lineno, text))

    # -- calls ---------------------------------------------------------------
    def _argument_name(self, call: ast.Call) -> str | None:
        given = call.args[0] if call.args else _keyword(call, ("name",))
        given = self._follow(given) if given is not None else None
        return _text(given)

    def _node(self, call: ast.Call) -> NodeEntry:
        if any(k.arg is None for k in call.keywords):
            self.unread.append(
                Unread(call.lineno, "Node(**...): keywords given as a dictionary are not read")
            )
        package = self._plain(call, ("package",), "package")
        executable = self._plain(call, KEYWORDS["executable"], "executable")
        name = _text(self._follow(_keyword(call, KEYWORDS["name"]) or ast.Constant(None)))
        params: list[ParamSetting] = []
        given = _keyword(call, ("parameters",))
        if given is not None:
            self._parameters(given, params)
        return NodeEntry(call.lineno, package, executable, name, tuple(params))

    def _plain(self, call: ast.Call, names: tuple[str, ...], label: str) -> str | None:
        """A keyword's plain text; what is not plain text is said once, here."""
        given = _keyword(call, names)
        if given is None:
            self.unread.append(Unread(call.lineno, f"Node(...) gives no {label}="))
            return None
        value = _text(self._follow(given))
        if value is None:
            self._runtime(given, label + "={}", "that node is not checked")
        return value

    def _parameters(self, given: ast.expr, params: list[ParamSetting]) -> None:
        items = self._follow(given)
        if not isinstance(items, ast.List | ast.Tuple):
            self._runtime(given, "parameters={}", "its parameters are not checked")
            return
        for item in items.elts:
            value = self._follow(item.value if isinstance(item, ast.Starred) else item)
            if isinstance(value, ast.Dict) and not isinstance(item, ast.Starred):
                self._dictionary(value, "", params)
            else:
                what = "parameters from {} (a parameter file or an expression)"
                self._runtime(item, what, verb="are")

    def _dictionary(self, given: ast.Dict, prefix: str, params: list[ParamSetting]) -> None:
        for key, value in zip(given.keys, given.values, strict=True):
            if key is None:
                self._runtime(value, "**{} in parameters=")
                continue
            name = _text(self._follow(key))
            if name is None:
                self._runtime(key, "parameter name {}")
                continue
            inner = self._follow(value)
            if isinstance(inner, ast.Dict):
                self._dictionary(inner, f"{prefix}{name}.", params)
            else:
                params.append(ParamSetting(prefix + name, key.lineno))


def _keyword(call: ast.Call, names: tuple[str, ...]) -> ast.expr | None:
    return next((k.value for name in names for k in call.keywords if k.arg == name), None)


def _text(expr: ast.expr | None) -> str | None:
    return expr.value if isinstance(expr, ast.Constant) and isinstance(expr.value, str) else None


def _imports(tree: ast.Module) -> dict[str, str]:
    """Each local name an import binds -> the module path it stands for."""
    names: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:  # `import a.b` binds a; `import a.b as c` binds c
                first = alias.name.split(".")[0]
                names[alias.asname or first] = alias.name if alias.asname else first
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            for alias in node.names:
                if alias.name == "*":
                    for star in STAR_NAMES.get(node.module, ()):
                        names[star] = f"{node.module}.{star}"
                else:
                    names[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    return names


def _single_assignments(tree: ast.Module) -> dict[str, ast.expr]:
    """Names bound exactly once, by a plain assignment of a dict, list or tuple literal
    (or of another name), and never changed in place: the values to follow."""
    bound: dict[str, int] = {}
    values: dict[str, ast.expr] = {}
    changed: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store | ast.Del):
            bound[node.id] = bound.get(node.id, 0) + 1
        elif isinstance(node, ast.arg):
            bound[node.arg] = bound.get(node.arg, 0) + 1
        elif isinstance(node, ast.Assign | ast.AnnAssign) and node.value is not None:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                if isinstance(target, ast.Name):
                    values[target.id] = node.value
                elif isinstance(target, ast.Subscript) and isinstance(target.value, ast.Name):
                    changed.add(target.value.id)
        elif isinstance(node, ast.AugAssign) and isinstance(node.target, ast.Name):
            changed.add(node.target.id)
        elif (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name)
            and node.func.attr in MUTATORS
        ):
            changed.add(node.func.value.id)
    literal = ast.Dict | ast.List | ast.Tuple | ast.Name | ast.Constant
    return {
        name: value
        for name, value in values.items()
        if bound.get(name) == 1 and name not in changed and isinstance(value, literal)
    }
