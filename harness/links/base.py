"""The small interface every link shares, and the registry that names them."""

from __future__ import annotations

import importlib
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, TypeVar

from harness.errors import ConfigError
from harness.links.kinds import link_kind
from harness.nodes.setup_problems import is_ros_module

if TYPE_CHECKING:  # naming the links and their options needs none of these (nor numpy)
    from harness.faults.link import LineDamage
    from harness.judge.answers import Answers, Received
    from harness.lidar.mount import LidarMount
    from harness.lidar.scan import Scan


@dataclass(frozen=True)
class LinkOptions:
    """Settings a link may use; each link reads the ones that concern it."""

    threshold: float = 0.5
    scan_timeout: float = 1.0  # seconds to wait for the answers to one scan
    ready_timeout: float = 20.0  # seconds to wait for the node to come up
    processor: str | None = None  # inprocess: "module:function" instead of the reference
    node: str | None = None  # shell command starting the node under test
    package: str | None = None
    executable: str | None = None
    workspace: str | None = None
    launch: tuple[str, str] | None = None  # (PACKAGE, FILE): start the node by `ros2 launch`
    params: tuple[str, ...] = ()  # NAME:=VALUE items passed to the node verbatim
    threshold_param: str | None = "threshold"  # node parameter that gets the threshold
    domain_id: int | None = None  # None: reserve a free one for this run
    ros_network: bool = False  # False: localhost-only discovery
    scan_topic: str = "/scan"
    status_topic: str = "/lidar_status"
    warning_topic: str = "/obstacle_warning"
    # The node's parameters that name its scan, status and warning topics (the lab's).
    topic_params: tuple[str, str, str] = ("lidar_topic", "lidar_status_topic", "warning_topic")
    realtime: bool = False
    port: str | None = None  # serial links: a real adapter wired to a board (None: virtual board)
    scan_rate_hz: float = 10.0  # the scenario's LIDAR rate (the runner fills it in)
    # Serial links, virtual board: the board's own software instead of the bundled
    # driver, each a command line in which {port} is the emulated device's path.
    board_commands: tuple[str, ...] = ()
    # Serial links: how the device sits on the robot (None: what the robot model says;
    # the runner fills it in).
    lidar_mount: LidarMount | None = None
    # A missed deadline ends the run (RunSettings.stop_at_first_failure): no wait for the
    # late answer to keep it from the next scan, as no next scan goes (the runner sets it).
    late_ends_run: bool = False


class Link(ABC):
    """Deliver one scan at a time and gather what the software under test says."""

    name: ClassVar[str]
    serial_line: ClassVar[bool] = False  # scans travel as device bytes on a serial line
    # A scenario's node_topics are set through the node's topic parameters (the harness
    # publishes the scans itself, so it can publish them on any topic).
    sets_node_topics: ClassVar[bool] = False
    node_start = ""  # how the node under test was started, for the user

    def __init__(self, options: LinkOptions) -> None:
        self.options = options
        # On a run-long device session: seconds between the previous scenario's last
        # judged revolution and this one's first (None where there is no session).
        self.gap_s: float | None = None

    @classmethod
    def run_session(cls, options: LinkOptions) -> AbstractContextManager[Any]:
        """What a run's links share (given to ``create_link``), as a context manager for the run."""
        return nullcontext(None)

    # A suite may start the next scenarios' links while one runs (`start`)
    # and let finished ones stop while the next runs (`stop`, then `close`).
    # Links whose software under test cannot be isolated that way say no.
    starts_ahead: ClassVar[bool] = False

    @classmethod  # noqa: B027 - optional hook
    def prepare(cls, options: LinkOptions) -> None:
        """Get ready for links with these options while the caller does other work (optional)."""

    def start(self) -> None:  # noqa: B027 - optional hook
        """Begin bringing the software under test up, without waiting for it."""

    def open(self) -> None:  # noqa: B027 - optional hook
        """Bring the software under test up (unless `start` did); wait, bounded, for readiness."""

    def warm_up(self, scan: Scan) -> None:  # noqa: B027 - optional hook
        """Make sure answers to `scan` can reach us (answers discarded): an untimed first
        exchange for the benchmarks, and before a run whose first scan may be ignored."""

    def send_first(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        """Deliver the run's first scan, judged like any other; a link whose software may miss a
        scan while it comes up (a ROS graph still matching) resends it until answered, bounded."""
        self.send(scan, tick, clock=clock)

    @abstractmethod
    def send(self, scan: Scan, tick: int, *, clock: float | None = None) -> None:
        """Deliver one scan; `clock` is the time it is now (default: its stamp)."""

    @abstractmethod
    def collect(self, scan: Scan, tick: int, *, may_be_ignored: bool = False) -> Answers:
        """Wait (bounded by options.scan_timeout) for the answers to the last scan;
        `may_be_ignored`: silence is right (a duplicate, an old scan), so no catch-up wait
        and no count toward the node going quiet."""

    def exchange(
        self, scan: Scan, tick: int, *, clock: float | None = None, may_be_ignored: bool = False
    ) -> Answers:
        """Lockstep: send a scan, then collect its answers."""
        self.send(scan, tick, clock=clock)
        return self.collect(scan, tick, may_be_ignored=may_be_ignored)

    def hold(self, seconds: float) -> None:
        """Let `seconds` pass before the next scan goes out (a delayed scan)."""
        time.sleep(seconds)

    def damage_line(self, damage: LineDamage) -> None:
        """Serial links: damage the device's bytes from now on."""
        raise ConfigError(f"line faults need a serial link, not {self.name!r}")

    def settle(self) -> list[Received]:
        """After the last scan: answers still on their way, each tagged with its tick."""
        return []

    def diagnostics(self) -> str:
        """Extra text for failure reports (e.g. the node's last stderr lines)."""
        return ""

    def notices(self) -> list[str]:
        """After the run, before `diagnostics`: notes on how the software is wired, true for the
        whole run (e.g. its warning on another topic); reports print each once."""
        return []

    def stop(self) -> None:  # noqa: B027 - optional hook
        """Ask everything this link started to stop, without waiting (`close` waits)."""

    def close(self) -> None:  # noqa: B027 - optional hook
        """Stop everything this link started, wait for it and reap it; safe to call twice."""

    def stop_note(self) -> str:
        """After `close`: anything stopping took beyond the usual (signals, leftovers)."""
        return ""

    def __enter__(self) -> Link:
        self.open()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Part:
    """A link's attribute that is one of its parts' (``part``: its graph, its exchange)."""

    def __init__(self, part: str) -> None:
        self.part = part

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, link: Any, owner: type | None = None) -> Any:
        return self if link is None else getattr(getattr(link, self.part), self.name)


ROS_WHEELS = "install the ROS 2 wheels: pip install 'fossbot-hil[ros]', or source ROS 2 Jazzy"
_REGISTRY: dict[str, type[Link]] = {}
L = TypeVar("L", bound=type[Link])
M = TypeVar("M")


def register(name: str) -> Callable[[L], L]:
    """Class decorator: make a link available under `name` (once), as ``kinds`` declares
    it: a class whose own ClassVars say otherwise than its row is refused."""

    return lambda cls: add_link(name, cls)


def add_link(name: str, link: M) -> M:
    """Make `link` (a ``Link`` class, or what makes links as one does: a serial LIDAR's
    ``board.SerialLidar``) available under `name`, checked against its ``kinds`` row."""
    known = _REGISTRY.get(name)
    if known is not None and _where(known) != _where(link):  # a re-import may replace it
        raise RuntimeError(f"link {name!r} is registered twice")
    kind = link_kind(name)
    serial_line = link.serial_line  # type: ignore[attr-defined]
    if serial_line != kind.serial_line:
        raise RuntimeError(
            f"link {name!r}: the class says serial_line={serial_line}, "
            f"harness.links.kinds says {kind.serial_line}"
        )
    link.name = name  # type: ignore[attr-defined]
    _REGISTRY[name] = link  # type: ignore[assignment]
    return link


def _where(link: Any) -> str:
    return f"{link.__module__}.{getattr(link, '__qualname__', '')}"


def create_link(name: str, options: LinkOptions, session: Any = None) -> Link:
    """The link registered as `name`, importing its module on first use; `session` is
    what its class's ``run_session`` gave the run, if anything."""
    cls = link_class(name)
    return cls(options) if session is None else cls(options, session=session)  # type: ignore[call-arg]


def link_class(name: str) -> type[Link]:
    """The class registered as `name`, importing its module (``kinds``) on first use."""
    if name not in _REGISTRY:
        kind = link_kind(name)  # ConfigError naming the known ones
        try:
            importlib.import_module(kind.module)
        except ImportError as err:
            hint = f" ({ROS_WHEELS})" if is_ros_module(err.name or "") else ""
            raise ConfigError(f"link {name!r} cannot start: {err}{hint}") from None
        if name not in _REGISTRY:
            raise RuntimeError(f"{kind.module} registers no link {name!r}")
    return _REGISTRY[name]
