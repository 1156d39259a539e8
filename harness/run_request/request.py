"""`RunRequest`: what one run is asked to do, from any caller's values, checked once."""

from __future__ import annotations

import os
import stat
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

from harness.errors import OptionError
from harness.run_request.table import option
from harness.run_request.values import literal

if TYPE_CHECKING:
    from harness.lidar.mount import LidarMount
    from harness.links.base import LinkOptions
    from harness.runner.settings import RunSettings

#: The options that choose the node under test (a link that runs none refuses them).
NODE_KEYS = ("node", "package", "executable", "workspace", "params")
#: The options that are not the link's: which link, how the scenarios are judged, and
#: the plugin's wait for a port; every other option is a LinkOptions field of its name.
RUN_KEYS = ("link", "seed", "faults", "threshold", "status_regex", "warning_when_clear")
OWN_KEYS = ("port_wait", "given")


@dataclass(frozen=True)
class RunRequest:
    """One run's options (a field per table row; None: not given, the scenario's or the
    link's own). `given` names the keys the caller's user gave (a file's value yields
    to a typed one only there)."""

    link: str | None = None  # None: the caller's default link
    node: str | None = None
    package: str | None = None
    executable: str | None = None
    workspace: str | None = None
    params: tuple[str, ...] = ()
    threshold_param: str | None = "threshold"
    scan_topic: str = "/scan"
    status_topic: str = "/lidar_status"
    warning_topic: str = "/obstacle_warning"
    ready_timeout: float = 20.0
    domain_id: int | None = None
    ros_network: bool = False
    realtime: bool = False
    port: str | None = None
    board_commands: tuple[str, ...] = ()
    lidar_mount: LidarMount | None = None
    launch: tuple[str, str] | None = None
    processor: str | None = None
    seed: int | None = None
    faults: str | tuple[str | dict[str, Any], ...] | None = None
    threshold: float | None = None
    status_regex: str | None = None
    warning_when_clear: str | None = None
    scan_timeout: float = 1.0
    port_wait: float = 300.0
    given: frozenset[str] = field(default=frozenset(), compare=False)

    @classmethod
    def of(
        cls,
        values: Mapping[str, object],
        given: Collection[str] = (),
        *,
        check: bool = True,
        typed: bool = False,
    ) -> RunRequest:
        """A request from `values` (keys of the table; text, or with `typed` only values
        of the option's type), each read by its row and (`check`) the whole checked;
        OptionError (keys as ``{key}``) for the first problem."""
        known = {f.name for f in fields(cls)} - {"given"}
        read: dict[str, Any] = {}
        for key, value in values.items():
            if key not in known:
                raise OptionError(key, f"unknown option {literal(key)}")
            row = option(key)
            if typed and row.number and isinstance(value, str):
                raise OptionError(key, f"{{{key}}} must be a number, got {literal(value)}")
            if row.repeat and value is not None:
                items = [value] if isinstance(value, str) else list(value)  # type: ignore[call-overload]
                read[key] = tuple(row.value(item) for item in items)
            elif value is not None or row.default is None:
                read[key] = row.value(value)
        request = cls(**read, given=frozenset(given))
        if check:
            request.check()
        return request

    def with_values(self, values: Mapping[str, object]) -> RunRequest:
        """This request with `values` where the user typed nothing (a file's settings:
        the command line's win), checked again."""
        kept = {key: value for key, value in values.items() if key not in self.given}
        mine = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "given"}
        return RunRequest.of({**mine, **kept}, self.given)

    # -- the checks ---------------------------------------------------------
    def check(self) -> None:
        """Combinations that cannot work; OptionError naming the options as ``{key}``."""
        if self.port is not None:
            check_port(self.port)  # a typo in the port is said first, whatever else is wrong
        self._check_node()
        if self.link is not None:
            self._check_link(self.link)
        if self.board_commands and self.port:
            raise OptionError(
                "board_commands",
                "{board_commands} runs the board's software on the virtual board; with "
                "{port} the physical board runs its own",
            )

    def _check_node(self) -> None:
        if self.node and (self.package or self.executable):
            other = "package" if self.package else "executable"
            raise OptionError("node", f"{{node}} and {{{other}}}: give one or the other")
        if self.launch and (self.node or self.package or self.executable):
            raise OptionError(
                "launch", "{launch} starts the node itself: drop {node}/{package}/{executable}"
            )
        if bool(self.package) != bool(self.executable):
            raise OptionError("package", "{package} and {executable} go together")

    def _check_link(self, link: str) -> None:
        from harness.links.kinds import either, link_kind, link_names, serial_links

        kind = link_kind(link)
        serial = either(serial_links())
        for key in ("port", "board_commands", "lidar_mount"):
            if getattr(self, key) not in (None, ()) and not kind.serial_line:
                why = f" (the {link} link sends the scan frame itself)"
                tail = why if key == "lidar_mount" else f", not {link}"
                raise OptionError(key, f"{{{key}}} needs {{link}} {serial}{tail}")
        if self.launch and not kind.launches:
            launched = either([n for n in link_names() if link_kind(n).launches])
            raise OptionError("launch", f"{{launch}} needs {{link}} {launched}, not {link}")
        if self.processor and kind.runs_node:
            functions = either([n for n in link_names() if not link_kind(n).runs_node])
            why = f"(the {link} link runs a node)"
            raise OptionError("processor", f"{{processor}} needs {{link}} {functions} {why}")
        if not kind.runs_node:
            for key in NODE_KEYS:
                if getattr(self, key):
                    raise OptionError(
                        key, f"{{{key}}} needs a link that runs a node, not {{link}} {link}"
                    )

    # -- what the lower layers take -------------------------------------------
    def link_options(self) -> LinkOptions:
        """The link's settings (the runner fills in the threshold and the scan rate)."""
        from harness.links.base import LinkOptions

        link = {key: getattr(self, key) for key in link_keys()}
        return LinkOptions(**{**link, "threshold_param": self.threshold_param or None})

    def run_settings(self) -> RunSettings:
        """The run's overrides of the scenarios' seed, threshold, faults and judging."""
        from harness.runner.settings import RunSettings

        return RunSettings(
            seed=self.seed,
            threshold=self.threshold,
            faults=self.fault_items(),
            status_pattern=self.status_regex,
            warning_when_clear=self.warning_when_clear,
        )

    def fault_items(self) -> list[str | dict[str, Any]] | None:
        """`faults` as a list of profile names and inline faults; None: the scenarios'."""
        if not self.faults:
            return None
        if isinstance(self.faults, str):
            from harness.faults.sensor import split_fault_text

            return list(split_fault_text(self.faults))
        return list(self.faults)


def check_port(path: str, key: str = "port") -> None:
    """A port the user named must be a device (a tty), checked before it is locked or opened,
    so a typo leaves nothing behind."""
    shown = literal(path, 200)[1:-1]
    if not path.strip():
        raise OptionError(key, f"{{{key}}} must not be empty")
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise OptionError(key, f"{{{key}}} {shown}: no such device") from None
    except (OSError, ValueError) as err:
        why = literal(getattr(err, "strerror", None) or str(err), 200)[1:-1]
        raise OptionError(key, f"{{{key}}} {shown}: {why}") from None
    if stat.S_ISDIR(mode):
        raise OptionError(key, f"{{{key}}} {shown}: a folder, not a serial port")
    if not stat.S_ISCHR(mode):
        raise OptionError(key, f"{{{key}}} {shown}: not a serial port (not a character device)")


def link_keys() -> tuple[str, ...]:
    """The request's keys that are LinkOptions fields, in the table's order."""
    return tuple(f.name for f in fields(RunRequest) if f.name not in (*RUN_KEYS, *OWN_KEYS))
