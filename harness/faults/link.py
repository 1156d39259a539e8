"""Seeded faults of the link between the LIDAR and the node (pure: numpy only).

Scan faults (``sensor``) change what a scan says; link faults how it travels
(late, lost, twice, out of order, a drifting rate, old stamps) and, on a
serial line, its bytes. Each kind draws a fixed number of times per scan (or
byte) from its own generator, seeded by the run's seed and the kind, so
adding a link fault never changes the scans, and one seed gives one plan.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar, get_args

import numpy as np

from harness.errors import ConfigError

__all__ = [
    "LINK_KINDS",
    "LINE_KINDS",
    "Delay",
    "Delivery",
    "Drop",
    "Duplicate",
    "LineCorruption",
    "LineDrops",
    "LineNoise",
    "LinkFaults",
    "NO_LINK_FAULTS",
    "ON_TIME",
    "RateDrift",
    "RateFault",
    "Reorder",
    "StaleStamps",
    "damage_bytes",
    "plan_deliveries",
    "scan_periods",
]

MAX_DELAY_S = 2.0
MAX_JITTER_S = 1.0
MAX_STAMP_AGE_S = 60.0
MIN_DRIFT_HZ, MAX_DRIFT_HZ = 0.5, 20.0
MAX_BYTE_RATE = 0.1  # beyond this a line carries noise, not a protocol
MAX_NOISE_BYTES = 1024
DRIFT_STEP = 0.15  # one scan's rate change, as a fraction of the drift range (one sigma)

# Stream ids: each kind's generator is default_rng([seed, id]); 0 is never used,
# so no link stream equals the scan faults' default_rng(seed).
_STREAM = {"delivery": 1, "drift": 2, "line": 3}


def _number(value: Any) -> bool:
    """A finite int or float (a bool is neither here)."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    return ok and math.isfinite(value)


def _rate(value: float, what: str, top: float = 1.0) -> None:
    if not (_number(value) and 0.0 <= value <= top):
        raise ConfigError(f"{what} must be in [0, {top:g}], got {value!r}")


def _seconds(value: float, what: str, top: float, *, positive: bool = False) -> None:
    if not (_number(value) and (value > 0 if positive else value >= 0) and value <= top):
        low = "(0" if positive else "[0"
        raise ConfigError(f"{what} must be in {low}, {top:g}] s, got {value!r}")


@dataclass(frozen=True)
class Delay:
    """Each scan reaches the node `mean` s late, give or take `jitter` s (uniform)."""

    mean: float
    jitter: float = 0.0
    kind: ClassVar[str] = "delay"
    params: ClassVar[tuple[str, ...]] = ("mean", "jitter")

    def __post_init__(self) -> None:
        _seconds(self.mean, "delay mean", MAX_DELAY_S)
        _seconds(self.jitter, "delay jitter", MAX_JITTER_S)

    def describe(self) -> str:
        spread = f" ± {self.jitter:g} s" if self.jitter else ""
        return f"scans delayed {self.mean:g} s{spread}"


@dataclass(frozen=True)
class RateFault:
    """A fault that strikes a fraction `rate` (at most `top`) of scans, beams or bytes."""

    rate: float
    kind: ClassVar[str]
    says: ClassVar[str]  # describe()'s words, formatted with the rate
    top: ClassVar[float] = 1.0
    params: ClassVar[tuple[str, ...]] = ("rate",)

    def __post_init__(self) -> None:
        _rate(self.rate, f"{self.kind} rate", self.top)

    def describe(self) -> str:
        return self.says.format(self.rate)


@dataclass(frozen=True)
class Drop(RateFault):
    """A fraction of the scans never reaches the node."""

    kind: ClassVar[str] = "drop"
    says: ClassVar[str] = "{:.0%} of scans dropped"


@dataclass(frozen=True)
class Duplicate(RateFault):
    """A fraction of the scans reaches the node twice."""

    kind: ClassVar[str] = "duplicate"
    says: ClassVar[str] = "{:.0%} of scans delivered twice"


@dataclass(frozen=True)
class Reorder(RateFault):
    """A fraction of the scans is held back and arrives after the next one."""

    kind: ClassVar[str] = "reorder"
    says: ClassVar[str] = "{:.0%} of scans swapped with the next"


@dataclass(frozen=True)
class RateDrift:
    """The scan rate wanders between `min_hz` and `max_hz` (the lab LIDAR: 3.3 to 6.7)."""

    min_hz: float = 3.3
    max_hz: float = 6.7
    kind: ClassVar[str] = "rate_drift"
    params: ClassVar[tuple[str, ...]] = ("min_hz", "max_hz")

    def __post_init__(self) -> None:
        for name in ("min_hz", "max_hz"):
            value = getattr(self, name)
            if not (_number(value) and MIN_DRIFT_HZ <= value <= MAX_DRIFT_HZ):
                raise ConfigError(
                    f"rate_drift {name} must be in [{MIN_DRIFT_HZ:g}, {MAX_DRIFT_HZ:g}] Hz, "
                    f"got {value!r}"
                )
        if self.min_hz > self.max_hz:
            raise ConfigError(
                f"rate_drift min_hz ({self.min_hz:g}) is above max_hz ({self.max_hz:g})"
            )

    def describe(self) -> str:
        return f"scan rate drifting between {self.min_hz:g} and {self.max_hz:g} Hz"


@dataclass(frozen=True)
class StaleStamps:
    """A fraction of the scans carries a header stamp `age` s older than the clock."""

    rate: float
    age: float = 1.0
    kind: ClassVar[str] = "stale_stamps"
    params: ClassVar[tuple[str, ...]] = ("rate", "age")

    def __post_init__(self) -> None:
        _rate(self.rate, "stale_stamps rate")
        _seconds(self.age, "stale_stamps age", MAX_STAMP_AGE_S, positive=True)

    def describe(self) -> str:
        return f"{self.rate:.0%} of scans stamped {self.age:g} s in the past"


@dataclass(frozen=True)
class LineCorruption(RateFault):
    """Serial links: each byte has one bit flipped with probability `rate`."""

    kind: ClassVar[str] = "line_corruption"
    says: ClassVar[str] = "{:.2%} of line bytes with a flipped bit"
    top: ClassVar[float] = MAX_BYTE_RATE


@dataclass(frozen=True)
class LineDrops(RateFault):
    """Serial links: each byte is lost with probability `rate`."""

    kind: ClassVar[str] = "line_drops"
    says: ClassVar[str] = "{:.2%} of line bytes lost"
    top: ClassVar[float] = MAX_BYTE_RATE


@dataclass(frozen=True)
class LineNoise:
    """Serial links: with probability `rate` per revolution, `length` random bytes (a glitch)."""

    rate: float
    length: int = 16
    kind: ClassVar[str] = "line_noise"
    params: ClassVar[tuple[str, ...]] = ("rate", "length")

    def __post_init__(self) -> None:
        _rate(self.rate, "line_noise rate")
        ok = isinstance(self.length, int) and not isinstance(self.length, bool)
        if not (ok and 1 <= self.length <= MAX_NOISE_BYTES):
            raise ConfigError(
                f"line_noise length must be a whole number of bytes in [1, {MAX_NOISE_BYTES}], "
                f"got {self.length!r}"
            )

    def describe(self) -> str:
        return f"{self.length}-byte noise bursts in {self.rate:.0%} of revolutions"


LinkFault = (
    Delay
    | Drop
    | Duplicate
    | Reorder
    | RateDrift
    | StaleStamps
    | LineCorruption
    | LineDrops
    | LineNoise
)
#: kind -> class, for the ``faults:`` list. Delivery kinds first, then the line kinds.
LINK_KINDS: dict[str, type[Any]] = {cls.kind: cls for cls in get_args(LinkFault)}
LINE_KINDS = ("line_corruption", "line_drops", "line_noise")
F = TypeVar("F")


@dataclass(frozen=True)
class LinkFaults:
    """The link faults of one run, at most one of each kind."""

    items: tuple[LinkFault, ...] = ()

    def __post_init__(self) -> None:
        order = list(LINK_KINDS)
        ordered = tuple(sorted(self.items, key=lambda f: order.index(f.kind)))
        object.__setattr__(self, "items", ordered)

    def get(self, kind: str) -> Any:
        return next((f for f in self.items if f.kind == kind), None)

    def __bool__(self) -> bool:
        return bool(self.items)

    @property
    def on_line(self) -> bool:
        """Damages serial bytes: only a serial link can carry these."""
        return any(f.kind in LINE_KINDS for f in self.items)

    @property
    def stale_stamps(self) -> bool:
        return self.get("stale_stamps") is not None

    def describe(self) -> str:
        return "; ".join(f.describe() for f in self.items)


@dataclass(frozen=True)
class Delivery:
    """How one scan travels to the node, and what the oracle may accept for it."""

    kind: str = "sent"  # sent, dropped, duplicate (second copy), reordered (after the next)
    delay_s: float = 0.0  # held this long before it goes out
    stamp_age_s: float = 0.0  # its header stamp is this much older than its time

    @property
    def delivered(self) -> bool:
        return self.kind != "dropped"

    @property
    def may_be_ignored(self) -> bool:
        """No answer is right too: the node saw this scan or a newer one, or its stamp is stale."""
        return self.kind in ("duplicate", "reordered") or self.stamp_age_s > 0

    def describe(self) -> str:
        """Words for reports; empty for a plain, on-time delivery."""
        words = {
            "dropped": "dropped by the link: no answer expected",
            "duplicate": "a second copy of this scan",
            "reordered": "delivered after the next scan",
        }
        parts = [words[self.kind]] if self.kind in words else []
        if self.delay_s > 0 and self.delivered:
            parts.append(f"delivered {self.delay_s:.3f} s late")
        if self.stamp_age_s > 0 and self.delivered:
            parts.append(f"stamped {self.stamp_age_s:g} s in the past")
        if self.may_be_ignored:
            parts.append("no answer accepted too")
        return ", ".join(parts)


ON_TIME = Delivery()  # a plain delivery: no link fault touched it
NO_LINK_FAULTS = LinkFaults()


def _stream(seed: int, name: str) -> np.random.Generator:
    return np.random.default_rng([int(seed) & (2**63 - 1), _STREAM[name]])


def plan_deliveries(
    frames: Iterable[F], faults: LinkFaults, seed: int
) -> Iterator[tuple[F, Delivery]]:
    """Each frame with how it travels, in the order the node receives them.

    A dropped frame still comes out (kind "dropped") so it can be recorded
    and judged as "no answer expected". Five draws per frame, whatever the
    faults, keep the plan of each kind independent of the others.
    """
    drop, dup, reorder = faults.get("drop"), faults.get("duplicate"), faults.get("reorder")
    stale, delay = faults.get("stale_stamps"), faults.get("delay")
    rng = _stream(seed, "delivery")
    held: tuple[F, Delivery] | None = None
    for frame in frames:
        u = rng.random(5)
        wait = 0.0
        if delay is not None:
            wait = max(0.0, delay.mean + delay.jitter * (2.0 * float(u[4]) - 1.0))
        age = stale.age if stale is not None and u[3] < stale.rate else 0.0
        if drop is not None and u[0] < drop.rate:
            yield frame, Delivery("dropped")
        elif held is None and reorder is not None and u[2] < reorder.rate:
            held = (frame, Delivery("reordered", wait, age))
            continue
        else:
            yield frame, Delivery("sent", wait, age)
            if dup is not None and u[1] < dup.rate:
                yield frame, Delivery("duplicate", 0.0, age)
        if held is not None:
            yield held
            held = None
    if held is not None:  # nothing came after it: it goes out last, in order after all
        frame, late = held
        yield frame, Delivery("sent", late.delay_s, late.stamp_age_s)


def scan_periods(drift: RateDrift, nominal_hz: float, seed: int) -> Iterator[float]:
    """Seconds between consecutive scans: a bounded random walk of the rate."""
    rng = _stream(seed, "drift")
    low, high = drift.min_hz, drift.max_hz
    rate = min(max(nominal_hz, low), high)
    while True:
        yield 1.0 / rate
        rate += DRIFT_STEP * (high - low) * float(rng.standard_normal())
        # Reflect at the bounds, so the walk stays inside without sticking to them.
        while not low <= rate <= high and high > low:
            rate = 2 * low - rate if rate < low else 2 * high - rate
        rate = min(max(rate, low), high)


class LineDamage:
    """Damages the bytes a device writes, revolution by revolution, from one seed."""

    def __init__(self, faults: LinkFaults, seed: int) -> None:
        self.corruption = faults.get("line_corruption")
        self.drops = faults.get("line_drops")
        self.noise = faults.get("line_noise")
        self._rng = _stream(seed, "line")
        self.flipped = self.dropped = self.noise_bytes = 0

    def __bool__(self) -> bool:
        return any(f is not None for f in (self.corruption, self.drops, self.noise))

    def damage(self, data: bytes) -> bytes:
        """`data` as it arrives at the far end of the line."""
        return damage_bytes(data, self)


def damage_bytes(data: bytes, line: LineDamage) -> bytes:
    """Flip bits, lose bytes, then maybe insert a noise burst; counts what it did.

    Draws per call: three per byte plus two and `length` for the burst,
    whatever the rates, so one seed gives one damage pattern.
    """
    rng = line._rng
    raw = np.frombuffer(data, dtype=np.uint8).copy()
    u_flip, u_drop, bits = rng.random(raw.size), rng.random(raw.size), rng.integers(0, 8, raw.size)
    if line.corruption is not None:
        flip = u_flip < line.corruption.rate
        raw[flip] ^= (1 << bits[flip]).astype(np.uint8)
        line.flipped += int(flip.sum())
    if line.drops is not None:
        keep = u_drop >= line.drops.rate
        line.dropped += int(raw.size - keep.sum())
        raw = raw[keep]
    out = raw.tobytes()
    if line.noise is not None:
        u_burst, where = rng.random(), rng.random()
        burst = rng.integers(0, 256, line.noise.length, dtype=np.uint8).tobytes()
        if u_burst < line.noise.rate:
            at = int(where * (len(out) + 1))
            out = out[:at] + burst + out[at:]
            line.noise_bytes += len(burst)
    return out
