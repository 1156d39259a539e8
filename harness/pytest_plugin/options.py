"""The pytest plugin's options: command line first, then the ini file, then the default.

Each ``--hil-*`` option has an ini twin (``hil_node`` for ``--hil-node``)
except the port and the domain id, which belong to one machine and one
board. Values go through the same argument types as the ``fossbot-hil``
command, so a bad value is one usage line. Nothing here imports numpy,
rclpy or pybullet until an option is actually given: the plugin is loaded
into every pytest session of whoever installed the package.
"""

from __future__ import annotations

import argparse
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import pytest

from harness.links.kinds import (
    default_link,
    default_serial_link,
    either,
    link_kind,
    link_names,
    serial_links,
)

DEFAULT_TIMEOUT_S = 1.0
DEFAULT_READY_TIMEOUT_S = 20.0
DEFAULT_PORT_WAIT_S = 300.0  # a whole board run, in real time, may be ahead in the queue


def _lazy(name: str, *args: str) -> Callable[[str], Any]:
    """An argument type from harness.commands.arguments, imported on first use."""

    def parse(text: str) -> Any:
        from harness.commands import arguments

        fn = getattr(arguments, name)
        return (fn(*args) if args else fn)(text)

    parse.__name__ = name  # argparse names the type in its own messages
    return parse


def _link(text: str) -> str:
    if text not in link_names():
        raise argparse.ArgumentTypeError(
            f"unknown link {text!r} (known: {', '.join(link_names())})"
        )
    return text


@dataclass(frozen=True)
class _Option:
    """One ``--hil-*`` option and its ini twin (None: command line only)."""

    name: str  # the HilConfig field
    metavar: str
    help: str
    parse: Callable[[str], Any] | None = None
    ini: bool = True
    repeat: bool = False

    @property
    def flag(self) -> str:
        return "--hil-" + self.name.replace("_", "-")

    @property
    def ini_name(self) -> str:
        return "hil_" + self.name


OPTIONS = (
    _Option(
        "link",
        "NAME",
        f"link to the software under test: {default_link()} (default), "
        f"{', '.join(n for n in link_names() if n != default_link())}; hil tests on a board "
        f"use {default_serial_link()} unless this names "
        f"{either([n for n in serial_links() if n != default_serial_link()])}",
        _link,
    ),
    _Option("node", "CMD", 'node under test as a shell command, e.g. "python3 my_node.py"'),
    _Option("package", "PKG", "node under test: a package in a colcon workspace"),
    _Option("executable", "EXE", "executable of --hil-package"),
    _Option("workspace", "DIR", "colcon workspace of --hil-package (has install/)"),
    _Option(
        "param",
        "NAME:=VALUE",
        "node parameter, passed verbatim (repeatable; ini: hil_param, one per line)",
        _lazy("param"),
        repeat=True,
    ),
    _Option(
        "port",
        "DEV",
        "USB-UART wired to the board's LIDAR input (enables hil tests)",
        ini=False,
    ),
    _Option(
        "domain_id",
        "N",
        "ROS_DOMAIN_ID (default: a free one reserved per run; a board's: 0)",
        _lazy("domain_id"),
        ini=False,
    ),
    _Option("seed", "N", "seed for every run (default: each scenario's)", _lazy("seed")),
    _Option(
        "warning_when_clear",
        "RULE",
        "must the node publish warning False when nothing is within the threshold: "
        "optional (the lab's rule) or required (default: each scenario's, optional)",
        _lazy("warning_rule"),
    ),
    _Option(
        "timeout",
        "S",
        f"seconds to wait for the answers to one scan (default {DEFAULT_TIMEOUT_S:g})",
        _lazy("duration", "timeout"),
    ),
    _Option(
        "ready_timeout",
        "S",
        f"seconds for the node to come up (default {DEFAULT_READY_TIMEOUT_S:g})",
        _lazy("duration", "ready timeout"),
    ),
    _Option(
        "port_wait",
        "S",
        f"seconds to wait while another run uses --hil-port (default {DEFAULT_PORT_WAIT_S:g})",
        _lazy("duration", "port wait"),
    ),
)


def add_options(parser: pytest.Parser) -> None:
    """Register the ``--hil-*`` options (one group) and their ini twins."""
    group = parser.getgroup("fossbot-hil", "FOSSBot LIDAR scenarios (fossbot-hil)")
    for opt in OPTIONS:
        kwargs: dict[str, Any] = {"metavar": opt.metavar, "help": opt.help, "default": None}
        if opt.parse is not None:
            kwargs["type"] = opt.parse
        if opt.repeat:
            kwargs.update(action="append", default=[])
        group.addoption(opt.flag, dest="hil_" + opt.name, **kwargs)
        if opt.ini:
            if opt.repeat:
                parser.addini(opt.ini_name, f"default for {opt.flag}", type="linelist")
            else:
                parser.addini(opt.ini_name, f"default for {opt.flag}", type="string")


@dataclass(frozen=True)
class HilConfig:
    """The session's settings; `given` says where each came from, for messages."""

    link: str | None = None  # None: the default link for runs, the default serial one for a board
    node: str | None = None
    package: str | None = None
    executable: str | None = None
    workspace: str | None = None
    param: tuple[str, ...] = ()
    port: str | None = None
    domain_id: int | None = None
    seed: int | None = None
    warning_when_clear: str | None = None
    timeout: float = DEFAULT_TIMEOUT_S
    ready_timeout: float = DEFAULT_READY_TIMEOUT_S
    port_wait: float = DEFAULT_PORT_WAIT_S
    given: dict[str, str] = field(default_factory=dict, compare=False)

    @property
    def run_link(self) -> str:
        return self.link if self.link is not None else default_link()

    @property
    def board_link(self) -> str:
        return self.link if self.link in serial_links() else default_serial_link()

    def source(self, name: str) -> str:
        """How the user gave `name`: "--hil-node" or "hil_node in pytest.ini"."""
        return self.given.get(name, "--hil-" + name.replace("_", "-"))


def _from_ini(config: pytest.Config, opt: _Option, where: str) -> Any:
    raw = config.getini(opt.ini_name)
    if opt.repeat:
        items = [str(x).strip() for x in raw if str(x).strip()]
        if opt.parse is not None:
            items = [_parse_ini(opt, x, where) for x in items]
        return tuple(items) or None
    text = str(raw).strip() if raw else ""
    if not text:
        return None
    text = _expanded(opt, text, f"{opt.ini_name} in {where}")
    if opt.name == "workspace" and config.inipath is not None:
        text = str(config.inipath.parent / text)  # relative to the ini file, as its paths are
    return _parse_ini(opt, text, where) if opt.parse is not None else text


#: The options that give a command line or a path: ``~`` and ``$VAR`` in them are expanded
#: as a shell would (harness.shell_words); an ini file, or quotes, leave them to us.
COMMANDS = ("node",)
PATHS = ("workspace", "port")


def _expanded(opt: _Option, text: str, source: str) -> str:
    """`text` of `opt` expanded (a command line's words, or a path); a usage error naming
    `source` ("--hil-node", "hil_node in pytest.ini") for what cannot be."""
    if opt.name not in COMMANDS + PATHS:
        return text
    from harness.shell_words import NotExpanded, expand_command, expand_path

    try:
        return (expand_command if opt.name in COMMANDS else expand_path)(text)
    except NotExpanded as err:
        raise pytest.UsageError(f"{source} {text!r}: {err}") from None


def _parse_ini(opt: _Option, text: str, where: str) -> Any:
    assert opt.parse is not None
    try:
        return opt.parse(text)
    except argparse.ArgumentTypeError as err:
        raise pytest.UsageError(f"{opt.ini_name} in {where}: {err}") from None


def read_config(config: pytest.Config) -> HilConfig:
    """Settings from the command line, else the ini file, else the defaults."""
    where = config.inipath.name if config.inipath is not None else "the ini file"
    values: dict[str, Any] = {}
    given: dict[str, str] = {}
    for opt in OPTIONS:
        value = config.getoption("hil_" + opt.name)
        if opt.repeat:
            value = tuple(value) or None
        elif isinstance(value, str):
            value = _expanded(opt, value, opt.flag)
        if value is None and opt.ini:
            value = _from_ini(config, opt, where)
            if value is not None:
                given[opt.name] = f"{opt.ini_name} in {where}"
        if value is not None:
            values[opt.name] = value
    return HilConfig(**values, given=given)


def _workers(config: pytest.Config) -> int:
    """How many pytest-xdist workers this session starts (1 without xdist)."""
    count = getattr(config.option, "numprocesses", None)
    if isinstance(count, int):
        return count
    return int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1") or 1)


def check_config(cfg: HilConfig, config: pytest.Config) -> None:
    """Combinations that cannot work are usage errors now, not a failure in every test."""
    src = cfg.source
    if cfg.node and (cfg.package or cfg.executable):
        other = "package" if cfg.package else "executable"
        raise pytest.UsageError(f"{src('node')} and {src(other)}: give one or the other")
    if bool(cfg.package) != bool(cfg.executable):
        raise pytest.UsageError(f"{src('package')} and {src('executable')} go together")
    if cfg.link is not None and not link_kind(cfg.link).runs_node:
        for name in ("node", "package", "param"):
            if getattr(cfg, name):
                raise pytest.UsageError(
                    f"{src(name)} needs a link that runs a node, not --hil-link {cfg.link}"
                )
    if cfg.param:
        from harness.commands.node_names import check_parameters
        from harness.errors import ConfigError

        try:  # each item is checked as it is read; here: none given twice
            check_parameters(cfg.param, None, {"params": f"{src('param')} "})
        except ConfigError as err:
            raise pytest.UsageError(str(err)) from None
    if cfg.port is not None:
        from harness.commands.arguments import check_port
        from harness.errors import ConfigError

        try:
            check_port("--hil-port", cfg.port)  # a typo is a usage error, not N failed tests
        except ConfigError as err:
            raise pytest.UsageError(str(err)) from None
    if cfg.port is not None and cfg.link is not None and not link_kind(cfg.link).serial_line:
        raise pytest.UsageError(
            f"--hil-port drives a board through its LIDAR line: --hil-link must be "
            f"{either(serial_links())}, not {cfg.link}"
        )
    if cfg.domain_id is not None and cfg.port is None and _workers(config) > 1:
        raise pytest.UsageError(
            f"--hil-domain-id {cfg.domain_id} with {_workers(config)} xdist workers: every "
            "worker's runs would share that ROS domain and hear each other; leave it out "
            "(each run reserves a free one)"
        )
    if cfg.node or cfg.package:
        resolve_node(cfg.node, cfg.package, cfg.executable, cfg.workspace, src=src)


def resolve_node(
    node: str | None,
    package: str | None,
    executable: str | None,
    workspace: str | None,
    *,
    src: Callable[[str], str],
) -> None:
    """Find the node now (a missing file or package is a usage error), as the link will."""
    from harness.errors import ConfigError
    from harness.nodes.command import package_node, shell_node

    try:
        if node:
            shell_node(node)
        elif package and executable:
            package_node(package, executable, workspace)
    except ConfigError as err:
        raise pytest.UsageError(renamed(str(err), src)) from None


def renamed(message: str, src: Callable[[str], str]) -> str:
    """A node error worded for the CLI ("--node ...") worded for pytest ("--hil-node ...")."""
    return re.sub(
        r"(?<![\w-])--(node|package|executable|workspace)\b", lambda m: src(m[1]), message
    )
