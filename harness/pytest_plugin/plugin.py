"""The fossbot-hil pytest plugin (registered by entry point; no conftest needed).

A test asks for ``hil``: ``result = hil.run("approach_wall", threshold=0.4)``, then
``assert result.ok, result.explanation``. The node and the link come from ``--hil-*``
options or ``hil_*`` ini keys, mirrored by fixtures a conftest may override; tests
marked ``hil`` need a physical board and skip, saying why, without one. It imports no
rclpy, pybullet or numpy: it is loaded into every pytest session."""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import pytest

from harness.pytest_plugin.cases import MARKER, MARKER_HELP, HilCase
from harness.pytest_plugin.options import HilConfig, add_options, check_config, read_config

if TYPE_CHECKING:
    from harness.links.base import LinkOptions
    from harness.pytest_plugin.hil import Hil

__all__ = ["HilBoard", "HilCase", "NodeUnderTest"]

NO_BOARD = (
    "no physical board named: give --hil-port=/dev/ttyUSB0 (the USB-UART wired to the "
    "board's LIDAR input) and --hil-domain-id N (the board's ROS_DOMAIN_ID)"
)
_CONFIG = pytest.StashKey[HilConfig]()


@dataclass(frozen=True)
class NodeUnderTest:
    """The node to start: a shell command, or a package's executable; none: the reference."""

    command: str | None = None
    package: str | None = None
    executable: str | None = None
    workspace: str | None = None
    params: tuple[str, ...] = ()  # NAME:=VALUE, passed verbatim


@dataclass(frozen=True)
class HilBoard:
    """Where the board is: the adapter wired to its LIDAR input, and its ROS graph."""

    port: str
    domain_id: int
    link: str  # the device the board expects: rplidar or ldlidar

    def run_options(self) -> dict[str, Any]:
        """Keyword arguments for ``hil.run`` that send the scenario to this board (the session's
        node options are dropped: the board runs its own driver and node)."""
        node = dict.fromkeys(("node", "package", "executable", "workspace"), None)
        board = {"link": self.link, "port": self.port, "domain_id": self.domain_id}
        return {**board, "ros_network": True, **node, "params": ()}


# -- hooks --------------------------------------------------------------------
def pytest_addoption(parser: pytest.Parser) -> None:
    """The --hil-* options and their ini twins (harness.pytest_plugin.options)."""
    add_options(parser)


def pytest_configure(config: pytest.Config) -> None:
    """Markers, and the options read and checked once: a bad value stops the session."""
    config.addinivalue_line("markers", "hil: needs a physical FOSSBot board (--hil-port)")
    config.addinivalue_line("markers", MARKER_HELP)
    # ROS 2's message code imports lark, which imports modules Python 3.11
    # deprecates: noise in every test that runs a node, and not the user's to fix.
    config.addinivalue_line(
        "filterwarnings", "ignore:module 'sre_(parse|constants)' is deprecated:DeprecationWarning"
    )
    cfg = read_config(config)
    check_config(cfg, config)
    config.stash[_CONFIG] = cfg


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Without --hil-port, hil tests skip and say why (a port is never guessed)."""
    if config.stash[_CONFIG].port is not None:
        return
    skip = pytest.mark.skip(reason=NO_BOARD)
    for item in items:
        if item.get_closest_marker("hil"):
            item.add_marker(skip)


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """@pytest.mark.hil_scenarios: one hil_case per scenario and fault profile."""
    marker = metafunc.definition.get_closest_marker(MARKER)
    if marker is None:
        return
    from harness.errors import ConfigError
    from harness.pytest_plugin.cases import cases_from_marker

    if "hil_case" not in metafunc.fixturenames:
        pytest.fail(
            f"@pytest.mark.{MARKER} on {metafunc.function.__name__}: "
            "the test needs a hil_case argument",
            pytrace=False,
        )
    try:
        cases = cases_from_marker(marker.args, dict(marker.kwargs))
    except ConfigError as err:
        problem = str(err)  # failed outside the handler: no chained traceback
    else:
        metafunc.parametrize("hil_case", cases, ids=[c.id for c in cases])
        return
    pytest.fail(f"@pytest.mark.{MARKER}: {problem}", pytrace=False)


# -- fixtures -------------------------------------------------------------------
@pytest.fixture(scope="session")
def hil_config(pytestconfig: pytest.Config) -> HilConfig:
    """The session's ``--hil-*`` settings (command line, then ini, then defaults)."""
    return pytestconfig.stash[_CONFIG]


@pytest.fixture
def hil_node(hil_config: HilConfig) -> NodeUnderTest:
    """The node under test; override in a conftest to fix it for a project."""
    c = hil_config
    return NodeUnderTest(c.node, c.package, c.executable, c.workspace, params=c.param)


@pytest.fixture
def hil_link(hil_config: HilConfig) -> str:
    """The link ``hil.run`` uses: --hil-link, else ros2."""
    return hil_config.run_link


@pytest.fixture
def hil_link_options(hil_config: HilConfig, hil_node: NodeUnderTest, hil_link: str) -> LinkOptions:
    """Link settings for every run of the test (the runner fills in threshold and rate)."""
    from harness.links.base import LinkOptions
    from harness.links.kinds import link_kind

    physical = link_kind(hil_link).serial_line and hil_config.port is not None
    return LinkOptions(
        scan_timeout=hil_config.timeout,
        ready_timeout=hil_config.ready_timeout,
        node=hil_node.command,
        package=hil_node.package,
        executable=hil_node.executable,
        workspace=hil_node.workspace,
        params=tuple(hil_node.params),
        domain_id=hil_config.domain_id,
        ros_network=physical,  # a board is another machine: discover beyond localhost
        port=hil_config.port if physical else None,
    )


@pytest.fixture
def hil(
    request: pytest.FixtureRequest,
    hil_config: HilConfig,
    hil_link: str,
    hil_link_options: LinkOptions,
) -> Hil:
    """Runs scenarios: ``hil.run("approach_wall", threshold=0.4, faults="noisy")``."""
    from harness.pytest_plugin.hil import Hil

    return Hil(
        hil_link,
        hil_link_options,
        seed=hil_config.seed,
        warning_when_clear=hil_config.warning_when_clear,
        port_wait=hil_config.port_wait,
        base_dir=request.path.parent,
        record=lambda name, value: request.node.user_properties.append((name, value)),
    )


@pytest.fixture
def hil_case() -> HilCase:
    """Given by ``@pytest.mark.hil_scenarios(...)``; without the marker there is none."""
    pytest.fail(
        f"hil_case comes from @pytest.mark.{MARKER}(...) on the test, which it lacks", pytrace=False
    )


@pytest.fixture
def hil_board(hil_config: HilConfig) -> Iterator[HilBoard]:
    """The board named on the command line, held for this test (other workers wait, bounded
    by --hil-port-wait); hil tests run only when there is one."""
    if hil_config.port is None:
        pytest.skip(NO_BOARD)
    from harness.errors import ConfigError
    from harness.serial_line.port_lock import hold_port

    env_id = os.environ.get("ROS_DOMAIN_ID", "0")
    default_id = int(env_id) if env_id.isdigit() else 0
    domain = hil_config.domain_id if hil_config.domain_id is not None else default_id
    label = f"--hil-port {hil_config.port}"
    try:
        lock = hold_port(hil_config.port, hil_config.port_wait, label=label)
    except ConfigError as err:
        problem = str(err)  # failed outside the handler: no chained traceback
    else:
        with lock:
            yield HilBoard(hil_config.port, domain, hil_config.board_link)
        return
    pytest.fail(problem, pytrace=False)
