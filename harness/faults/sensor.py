"""Seeded fault profiles: the simulator's truth in, the emitted Scan out (pure).

Real sensors and drivers add noise, lose returns, report ghosts below
range_min and disagree on how to write "no return" and "too close"; a
``FaultProfile`` models that in one fixed pipeline::

    truth -> noise -> classify -> dropouts -> spurious -> convention -> float32 Scan

Every draw has a fixed size per fault (one number per beam), so one profile
and seed give byte-identical scans whatever the robot sees.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from harness.errors import ConfigError
from harness.faults.link import (
    LINK_KINDS,
    Delay,
    Drop,
    Duplicate,
    LineCorruption,
    LineDrops,
    LineNoise,
    LinkFault,
    LinkFaults,
    RateDrift,
    RateFault,
    Reorder,
    StaleStamps,
)
from harness.lidar.scan import Scan
from harness.lidar.spec import LidarSpec

__all__ = [
    "CONVENTIONS",
    "NAMED_PROFILES",
    "DROPOUT_VALUES",
    "Convention",
    "Dropouts",
    "FarReturns",
    "Fault",
    "FaultProfile",
    "Noise",
    "Spurious",
    "build_profile",
    "split_fault_text",
]

# Beam classes inside the pipeline.
_VALID, _TOO_CLOSE, _NO_RETURN, _DROPPED, _GHOST = 0, 1, 2, 3, 4

#: Intensity of a beam that carries a return (valid or spurious); 0 elsewhere.
RETURN_INTENSITY = 1.0

#: Driver conventions: name -> (no return, too close, who does it).
CONVENTIONS: dict[str, tuple[str, str, str]] = {
    "rep117": ("+inf", "-inf", "REP-117 as Gazebo publishes it"),
    "inf": ("+inf", "+inf", "rplidar_ros and the FOSSBot v2 bridge: every empty bin +inf"),
    "range_max": ("range_max", "-inf", "drivers that clamp no return to range_max"),
    "nan": ("nan", "nan", "LDROBOT LD06/LD19 vendor driver"),
    "zero": ("0", "0", "raw device distance 0 passed through"),
}

#: What a dropped return reads as.
DROPOUT_VALUES: dict[str, float] = {"nan": math.nan, "zero": 0.0, "inf": math.inf}


_ENCODED = {"+inf": math.inf, "-inf": -math.inf, "nan": math.nan, "0": 0.0}


def _encoded(word: str, range_max: float) -> float:
    return range_max if word == "range_max" else _ENCODED[word]


@dataclass(frozen=True)
class Noise:
    """Gaussian range noise on every true hit, before classification.

    Noise can push a hit across range_min or range_max; it is then classified
    (and encoded) like any other reading there.
    """

    sigma: float
    kind: ClassVar[str] = "noise"
    params: ClassVar[tuple[str, ...]] = ("sigma",)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.sigma) and 0 <= self.sigma <= 1.0):
            raise ConfigError(f"noise sigma must be in [0, 1] m, got {self.sigma}")

    def describe(self) -> str:
        return f"gaussian range noise sigma {self.sigma:g} m"


@dataclass(frozen=True)
class Dropouts(RateFault):
    """A fraction of the valid returns is lost and reads as ``value``."""

    value: str = "nan"
    kind: ClassVar[str] = "dropouts"
    params: ClassVar[tuple[str, ...]] = ("rate", "value")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.value not in DROPOUT_VALUES:
            known = ", ".join(DROPOUT_VALUES)
            raise ConfigError(f"dropouts value must be one of {known}, got {self.value!r}")

    def describe(self) -> str:
        return f"{self.rate:.0%} of valid returns read {self.value}"


@dataclass(frozen=True)
class Spurious(RateFault):
    """Ghost returns closer than range_min on a fraction of all beams.

    Values are drawn from [0.05, 0.95) * range_min, so they stay strictly
    inside (0, range_min) even after rounding to float32: invalid by REP-117,
    a trap for nodes that take ``min(ranges)`` without checking range_min.
    """

    kind: ClassVar[str] = "spurious"
    says: ClassVar[str] = "{:.0%} of beams read a ghost below range_min"


@dataclass(frozen=True)
class FarReturns(RateFault):
    """Finite readings beyond range_max on a fraction of the no-return beams.

    A device measures past the range_max its driver publishes (the
    datasheet's), and drivers that pass its raw distances through publish
    them: values drawn from [1.02, 1.25) * range_max, invalid by REP-117, a
    trap for nodes that do not check range_max.
    """

    kind: ClassVar[str] = "far_returns"
    says: ClassVar[str] = "{:.0%} of no-return beams read a raw distance beyond range_max"


@dataclass(frozen=True)
class Convention:
    """How the driver writes 'no return' and 'too close' (see ``CONVENTIONS``)."""

    name: str
    kind: ClassVar[str] = "convention"
    params: ClassVar[tuple[str, ...]] = ("name",)

    def __post_init__(self) -> None:
        _check_convention(self.name)

    def describe(self) -> str:
        no_return, too_close, _ = CONVENTIONS[self.name]
        return f"{self.name} convention (no return {no_return}, too close {too_close})"


Fault = Noise | Dropouts | Spurious | FarReturns
_Item = Noise | Dropouts | Spurious | FarReturns | Convention | LinkFault
_FAULT_ORDER: tuple[str, ...] = ("noise", "dropouts", "spurious", "far_returns")
_KINDS: dict[str, type[Any]] = {
    cls.kind: cls for cls in (Convention, Dropouts, FarReturns, Noise, Spurious)
} | LINK_KINDS


def _check_convention(name: str) -> None:
    if name not in CONVENTIONS:
        known = ", ".join(CONVENTIONS)
        raise ConfigError(f"unknown driver convention {name!r} (known: {known})")


@dataclass(frozen=True)
class FaultProfile:
    """A composition of faults plus a driver convention; ``emit`` applies them."""

    faults: tuple[Fault, ...] = ()
    convention: str = "rep117"
    name: str = "clean"
    link: LinkFaults = LinkFaults()  # how scans travel (see harness.faults.link)

    def __post_init__(self) -> None:
        _check_convention(self.convention)
        kinds = [f.kind for f in self.faults]
        if len(set(kinds)) != len(kinds):
            raise ConfigError(f"fault profile {self.name!r}: one fault of each kind, got {kinds}")
        # Store in pipeline order so equal profiles compare equal.
        ordered = tuple(sorted(self.faults, key=lambda f: _FAULT_ORDER.index(f.kind)))
        object.__setattr__(self, "faults", ordered)

    def _get(self, kind: str) -> Any:
        return next((f for f in self.faults if f.kind == kind), None)

    @property
    def noise_sigma(self) -> float:
        """Standard deviation of the range noise (0 without noise), for oracle tolerances."""
        noise = self._get("noise")
        return float(noise.sigma) if noise is not None else 0.0

    def describe(self) -> str:
        """One line for reports: the name and what it does."""
        parts = [f.describe() for f in self.faults] + [Convention(self.convention).describe()]
        if self.link:
            parts.append(self.link.describe())
        return f"{self.name}: " + "; ".join(parts)

    def emit(
        self, truth: np.ndarray, spec: LidarSpec, rng: np.random.Generator, *, stamp: float
    ) -> Scan:
        """Turn true distances (np.inf = no hit) into the scan a driver would publish."""
        truth = np.asarray(truth, dtype=np.float64)
        n = spec.samples
        if truth.shape != (n,):
            raise ValueError(f"truth has shape {truth.shape}, the LIDAR has {n} beams")
        values = truth.copy()
        values[np.isnan(values)] = np.inf  # defensive: a NaN truth is "no hit"

        noise = self._get("noise")
        if noise is not None:
            z = rng.standard_normal(n)
            hit = np.isfinite(values)
            values[hit] += noise.sigma * z[hit]

        # Classify in float32, as the node and the oracle compare (Scan.valid_mask).
        v32 = values.astype(np.float32)
        rmin, rmax = np.float32(spec.range_min), np.float32(spec.range_max)
        cls = np.full(n, _NO_RETURN, dtype=np.int8)
        with np.errstate(invalid="ignore"):
            cls[v32 < rmin] = _TOO_CLOSE
            cls[(v32 >= rmin) & (v32 <= rmax)] = _VALID

        dropouts = self._get("dropouts")
        if dropouts is not None:
            u = rng.random(n)
            lost = (cls == _VALID) & (u < dropouts.rate)
            v32[lost] = DROPOUT_VALUES[dropouts.value]
            cls[lost] = _DROPPED

        spurious = self._get("spurious")
        if spurious is not None:
            u = rng.random(n)
            ghost = rng.uniform(0.05, 0.95, n) * spec.range_min
            hit = u < spurious.rate
            v32[hit] = ghost[hit]
            cls[hit] = _GHOST  # a return, but an invalid one

        far = self._get("far_returns")
        if far is not None:
            u = rng.random(n)
            beyond = rng.uniform(1.02, 1.25, n) * spec.range_max
            hit = (cls == _NO_RETURN) & (u < far.rate)
            v32[hit] = beyond[hit]
            cls[hit] = _GHOST  # a return, but an invalid one

        no_return, too_close, _ = CONVENTIONS[self.convention]
        v32[cls == _NO_RETURN] = _encoded(no_return, spec.range_max)
        v32[cls == _TOO_CLOSE] = _encoded(too_close, spec.range_max)

        returned = (cls == _VALID) | (cls == _GHOST)
        intensities = np.where(returned, RETURN_INTENSITY, 0.0).astype(np.float32)
        return spec.scan(v32, intensities=intensities, stamp=float(stamp))


def _named(description: str, *items: _Item) -> tuple[str, tuple[_Item, ...]]:
    return description, items


# The building blocks of build_profile: a description and the items a name adds.
_NAMED: dict[str, tuple[str, tuple[_Item, ...]]] = {
    "clean": _named("no faults; REP-117 encoding (+inf no return, -inf too close)"),
    "noisy": _named("gaussian range noise, sigma 0.01 m", Noise(0.01)),
    "dropouts_nan": _named("5% of valid returns lost as NaN", Dropouts(0.05, "nan")),
    "dropouts_zero": _named("5% of valid returns lost as 0.0", Dropouts(0.05, "zero")),
    "dropouts_inf": _named("5% of valid returns lost as +inf", Dropouts(0.05, "inf")),
    "spurious_close": _named("2% of beams read a ghost below range_min", Spurious(0.02)),
    "beyond_range_max": _named(
        "5% of no-return beams read a raw distance beyond range_max", FarReturns(0.05)
    ),
    "driver_rep117": _named("REP-117: +inf no return, -inf too close", Convention("rep117")),
    "driver_rplidar_ros": _named(
        "rplidar_ros / FOSSBot v2 bridge: device distance 0 (no return or too close) as +inf",
        Convention("inf"),
    ),
    "driver_nan": _named(
        "LD06/LD19 vendor driver: NaN for no return and too close", Convention("nan")
    ),
    "driver_zero": _named("raw distance 0.0 for no return and too close", Convention("zero")),
    "driver_range_max": _named(
        "no return written as range_max (too close -inf)", Convention("range_max")
    ),
    "harsh": _named(
        "everything at once: noise 0.02 m, 10% NaN dropouts, 5% ghosts, NaN driver",
        Noise(0.02),
        Dropouts(0.10, "nan"),
        Spurious(0.05),
        Convention("nan"),
    ),
    "slow_link": _named("scans delayed 0.05 s ± 0.03 s", Delay(0.05, 0.03)),
    "lossy_link": _named(
        "10% of scans dropped, 5% delivered twice, 5% swapped with the next",
        Drop(0.10),
        Duplicate(0.05),
        Reorder(0.05),
    ),
    "drifting_rate": _named(
        "scan rate drifting between 3.3 and 6.7 Hz, as the lab robot's LIDAR", RateDrift(3.3, 6.7)
    ),
    "stale_stamps": _named("20% of scans stamped 1 s in the past", StaleStamps(0.2, 1.0)),
    "noisy_line": _named(
        "serial links: 0.01% of bytes with a flipped bit, 0.005% lost, "
        "16-byte noise in 3% of revolutions",
        LineCorruption(0.0001),
        LineDrops(0.00005),
        LineNoise(0.03, 16),
    ),
}


def _compose(items: Sequence[_Item], name: str) -> FaultProfile:
    """Later items replace earlier ones of the same kind."""
    by_kind: dict[str, _Item] = {}
    for item in items:
        by_kind[item.kind] = item
    convention = by_kind.pop("convention", Convention("rep117"))
    assert isinstance(convention, Convention)
    link = tuple(f for f in by_kind.values() if f.kind in LINK_KINDS)
    faults = tuple(f for f in by_kind.values() if f.kind in _FAULT_ORDER)
    return FaultProfile(faults=faults, convention=convention.name, name=name, link=LinkFaults(link))


#: name -> (description, profile); the names a scenario's ``faults:`` list may use.
NAMED_PROFILES: dict[str, tuple[str, FaultProfile]] = {
    name: (desc, _compose(items, name)) for name, (desc, items) in _NAMED.items()
}


def _inline(where: str, spec: Mapping[str, Any]) -> tuple[_Item, str]:
    """One inline dict -> a fault; ConfigError names the item and field."""
    known_kinds = ", ".join(sorted(_KINDS))
    if "type" not in spec:
        raise ConfigError(f"{where}: missing 'type' (known: {known_kinds})")
    kind = spec["type"]
    if not isinstance(kind, str) or kind not in _KINDS:
        raise ConfigError(f"{where}: unknown fault type {kind!r} (known: {known_kinds})")
    cls = _KINDS[kind]
    args = {k: v for k, v in spec.items() if k != "type"}
    for key in args:
        if key not in cls.params:
            raise ConfigError(
                f"{where}: unknown key {key!r} for {kind} (known: {', '.join(cls.params)})"
            )
    optional = {f.name for f in dataclasses.fields(cls) if f.default is not dataclasses.MISSING}
    for key in cls.params:
        if key not in args and key not in optional:
            raise ConfigError(f"{where}.{key}: required for {kind}")
        value = args.get(key)
        if value is None:
            continue
        if key in ("value", "name"):
            if not isinstance(value, str):
                raise ConfigError(f"{where}.{key}: must be a string, got {value!r}")
        elif key == "length":
            if isinstance(value, bool) or not isinstance(value, int):
                raise ConfigError(f"{where}.{key}: must be a whole number, got {value!r}")
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{where}.{key}: must be a number, got {value!r}")
        elif key in ("sigma", "rate") and not (math.isfinite(value) and 0 <= value <= 1):
            unit = " m" if key == "sigma" else ""
            raise ConfigError(f"{where}.{key}: must be in [0, 1]{unit}, got {value!r}")
        else:
            args[key] = float(value)
    try:
        item = cls(**args)
    except ConfigError as err:
        raise ConfigError(f"{where}: {err}") from None
    shown = (f"{k}={args[k]:g}" if isinstance(args[k], float) else f"{k}={args[k]}" for k in args)
    return item, f"{kind}({','.join(shown)})"


def build_profile(
    items: Sequence[str | Mapping[str, Any]], *, field_name: str = "faults"
) -> FaultProfile:
    """A scenario's ``faults:`` list -> one profile; later items override earlier kinds.

    Items are names from ``NAMED_PROFILES`` or inline dicts such as
    ``{type: noise, sigma: 0.01}``. Errors name the item, e.g.
    ``faults[1]: unknown fault type 'nosie' (known: ...)``.
    """
    if isinstance(items, (str, bytes)) or not isinstance(items, Sequence):
        raise ConfigError(f"{field_name}: must be a list of profile names or fault mappings")
    collected: list[_Item] = []
    labels: list[str] = []
    for i, entry in enumerate(items):
        where = f"{field_name}[{i}]"
        if isinstance(entry, str) and "(" not in entry:
            if entry not in _NAMED:
                known = ", ".join(_NAMED)
                raise ConfigError(f"{where}: unknown fault profile {entry!r} (known: {known})")
            collected.extend(_NAMED[entry][1])
            labels.append(entry)
            continue
        if isinstance(entry, str):
            entry = _call_mapping(where, entry)
        elif not isinstance(entry, Mapping):
            raise ConfigError(
                f"{where}: expected a profile name or a mapping with 'type', got {entry!r}"
            )
        item, label = _inline(where, entry)
        collected.append(item)
        labels.append(label)
    return _compose(collected, "+".join(labels) or "clean")


def _call_mapping(where: str, text: str) -> dict[str, Any]:
    """ "drop(rate=0.1)" -> {"type": "drop", "rate": 0.1}: inline faults on a command line."""
    kind, _, rest = text.strip().partition("(")
    if not rest.endswith(")"):
        raise ConfigError(f"{where}: {text!r}: expected KIND(KEY=VALUE,...)")
    spec: dict[str, Any] = {"type": kind.strip()}
    for part in filter(None, (p.strip() for p in rest[:-1].split(","))):
        key, eq, value = part.partition("=")
        if not eq or not key.strip():
            raise ConfigError(f"{where}: {text!r}: expected KEY=VALUE, got {part!r}")
        if key.strip() in spec:
            raise ConfigError(f"{where}: {text!r}: {key.strip()} given twice")
        spec[key.strip()] = _value(value.strip())
    return spec


def _value(text: str) -> Any:
    """A number if it reads as a finite one; words such as nan and inf stay words."""
    for convert in (int, float):
        try:
            number = convert(text)
        except ValueError:
            continue
        return number if math.isfinite(number) else text
    return text


def split_fault_text(text: str) -> list[str]:
    """ "noisy,drop(rate=0.1),delay(mean=0.05,jitter=0.01)" -> its three items.

    Commas inside parentheses belong to the item.
    """
    items, depth, start = [], 0, 0
    for i, char in enumerate(text):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if char == "," and depth == 0:
            items.append(text[start:i])
            start = i + 1
    items.append(text[start:])
    return [item.strip() for item in items if item.strip()]
