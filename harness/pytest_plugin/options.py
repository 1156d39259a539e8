"""The pytest plugin's options: command line first, then the ini file, then the default.

Each ``--hil-*`` option is a row of the run request's table with an ini twin (but the
port and the domain id, which belong to one machine); values are read as the CLI reads
them and checked by the session's `RunRequest`. Nothing heavy is imported until an
option is given: the plugin loads into every pytest session of whoever installed it."""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import pytest

from harness.commands.arguments import row_type
from harness.links.kinds import default_link, default_serial_link, either, link_names, serial_links
from harness.run_request import OPTIONS as TABLE
from harness.run_request import OptionError, RunOption, RunRequest, table


@dataclass(frozen=True)
class _Option:
    """One ``--hil-*`` option and its ini twin (None: command line only), from its row."""

    row: RunOption
    help: str

    @property
    def name(self) -> str:  # the HilConfig field
        assert self.row.hil is not None
        return self.row.hil

    @property
    def metavar(self) -> str | None:
        return self.row.hil_metavar or self.row.metavar

    @property
    def parse(self) -> Callable[[str], Any] | None:
        """The CLI's type: its problem in one line after "argument --hil-seed:" (or
        "hil_seed in tox.ini:")."""
        return row_type(self.row.key)


LINK_HELP = (
    f"link to the software under test: {default_link()} (default), "
    f"{', '.join(n for n in link_names() if n != default_link())}; hil tests on a board "
    f"use {default_serial_link()} unless this names "
    f"{either([n for n in serial_links() if n != default_serial_link()])}"
)
OPTIONS = tuple(
    _Option(row, LINK_HELP if row.key == "link" else row.hil_help or row.help)
    for row in TABLE
    if row.hil is not None
)


def add_options(parser: pytest.Parser) -> None:
    """Register the ``--hil-*`` options (one group) and their ini twins."""
    group = parser.getgroup("fossbot-hil", "FOSSBot LIDAR scenarios (fossbot-hil)")
    for opt in OPTIONS:
        kwargs: dict[str, Any] = {"metavar": opt.metavar, "help": opt.help, "default": None}
        if opt.parse is not None:
            kwargs["type"] = opt.parse
        if opt.row.repeat:
            kwargs.update(action="append", default=[])
        group.addoption(opt.row.hil_flag, dest="hil_" + opt.name, **kwargs)
        if opt.row.ini:
            kind = "linelist" if opt.row.repeat else "string"
            parser.addini(opt.row.ini_key, f"default for {opt.row.hil_flag}", type=kind)


@dataclass(frozen=True)
class HilConfig:
    """The session's settings; `given` says where each came from, for messages."""

    link: str | None = None  # None: the default link for runs, the default serial one for a board
    node: str | None = None
    package: str | None = None
    executable: str | None = None
    workspace: str | None = None
    param: tuple[str, ...] = table.option("params").default
    port: str | None = None
    domain_id: int | None = None
    seed: int | None = None
    warning_when_clear: str | None = None
    timeout: float = table.option("scan_timeout").default
    ready_timeout: float = table.option("ready_timeout").default
    port_wait: float = table.option("port_wait").default
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
    raw = config.getini(opt.row.ini_key)
    if opt.row.repeat:
        items = [str(x).strip() for x in raw if str(x).strip()]
        if opt.parse is not None:
            items = [_parse_ini(opt, x, where) for x in items]
        return tuple(items) or None
    text = str(raw).strip() if raw else ""
    if not text:
        return None
    text = _expanded(opt, text, f"{opt.row.ini_key} in {where}")
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
        raise pytest.UsageError(f"{opt.row.ini_key} in {where}: {err}") from None


def read_config(config: pytest.Config) -> HilConfig:
    """Settings from the command line, else the ini file, else the defaults."""
    where = config.inipath.name if config.inipath is not None else "the ini file"
    values: dict[str, Any] = {}
    given: dict[str, str] = {}
    for opt in OPTIONS:
        value = config.getoption("hil_" + opt.name)
        if opt.row.repeat:
            value = tuple(value) or None
        elif isinstance(value, str):
            value = _expanded(opt, value, opt.row.hil_flag)
        if value is None and opt.row.ini:
            value = _from_ini(config, opt, where)
            if value is not None:
                given[opt.name] = f"{opt.row.ini_key} in {where}"
        if value is not None:
            values[opt.name] = value
    return HilConfig(**values, given=given)


def _workers(config: pytest.Config) -> int:
    """How many pytest-xdist workers this session starts (1 without xdist)."""
    count = getattr(config.option, "numprocesses", None)
    if isinstance(count, int):
        return count
    return int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1") or 1)


#: The request's keys for the HilConfig fields (the rest are named alike).
_KEYS = {"param": "params", "timeout": "scan_timeout"}


def request_of(cfg: HilConfig) -> RunRequest:
    """The session's run request, checked once; a usage error naming each option as the
    user gave it ("--hil-node", "hil_node in pytest.ini")."""
    values = {_KEYS.get(opt.name, opt.name): getattr(cfg, opt.name) for opt in OPTIONS}
    try:
        return RunRequest.of(values)
    except OptionError as err:
        names = {_KEYS.get(opt.name, opt.name): cfg.source(opt.name) for opt in OPTIONS}
        problem = err.render(names)  # failed outside the handler: no chained traceback
    raise pytest.UsageError(problem)


def check_config(cfg: HilConfig, config: pytest.Config) -> None:
    """Combinations that cannot work are usage errors now, not a failure in every test."""
    src = cfg.source
    request_of(cfg)
    if cfg.param:
        from harness.commands.node_names import check_parameters
        from harness.errors import ConfigError

        try:  # each item is checked as it is read; here: none given twice
            check_parameters(cfg.param, None, {"params": f"{src('param')} "})
        except ConfigError as err:
            raise pytest.UsageError(str(err)) from None
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
    """Find the node now (a missing file or package is a usage error), as the link will;
    the problem names each option as the user gave it ("--hil-node", "hil_node in tox.ini")."""
    from harness.nodes.command import package_node, shell_node

    try:
        if node:
            shell_node(node)
        elif package and executable:
            package_node(package, executable, workspace)
    except OptionError as err:
        keys = ("node", "package", "executable", "workspace")
        raise pytest.UsageError(err.render({key: src(key) for key in keys})) from None
