"""The scans every bench stage measures: the lab's three scenarios, repeated.

Each stage runs the same scenarios with the same seeds, so its scans per
second compare with the ray-casting floor scan for scan. The runs are
chained into one stream of frames, so one link and one node serve them
all; building a world is a per-run cost, not a per-scan one, and is timed
apart.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Generator, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from harness.errors import ConfigError
from harness.faults.sensor import FaultProfile
from harness.judge.oracle import Oracle
from harness.runner.frames import Frame
from harness.runner.settings import RunSettings, effective_seed, effective_threshold, fault_profile
from harness.scenario.files import resolve_scenario
from harness.scenario.schema import Scenario

if TYPE_CHECKING:
    from harness.sim.simulation import Simulation

T = TypeVar("T")
LAB_TRIO = ("approach_wall", "drive_past_10m", "out_of_range")


@dataclass(frozen=True)
class Workload:
    """Scenarios run in turn, `repeats` times over, with one settings override."""

    scenarios: tuple[Scenario, ...]
    repeats: int = 1
    settings: RunSettings = RunSettings()

    @property
    def threshold(self) -> float:
        """The one threshold the node is started with (every scenario must share it)."""
        return _one({effective_threshold(s, self.settings) for s in self.scenarios}, "threshold")

    @property
    def scan_rate_hz(self) -> float:
        """The LIDAR rate the device emulators are built for (every scenario must share it)."""
        return _one({s.lidar_spec.rate_hz for s in self.scenarios}, "LIDAR rate")

    def runs(self) -> list[Scenario]:
        """Every scenario run, in order."""
        return [s for _ in range(self.repeats) for s in self.scenarios]

    def profiles(self) -> list[FaultProfile]:
        return [fault_profile(s, self.settings) for s in self.runs()]

    def oracle(self) -> Oracle:
        """One oracle for the chained stream (same threshold and noise for every run)."""
        sigma = _one({p.noise_sigma for p in self.profiles()}, "noise sigma")
        pattern = self.settings.status_pattern
        return Oracle(self.threshold, noise_sigma=sigma, status_pattern=pattern)


def _one(values: set[float], what: str) -> float:
    """The one value every scenario of a bench must share (one node serves them all)."""
    if len(values) != 1:
        raise ConfigError(f"bench scenarios need one {what}, got {sorted(values)}")
    return values.pop()


def lab_workload(repeats: int = 1, names: Sequence[str] = LAB_TRIO) -> Workload:
    """The lab's scenarios (approach a wall, drive past 10 m, out of range)."""
    return Workload(tuple(resolve_scenario(n) for n in names), repeats)


class FrameStream:
    """The workload's frames, chained; iterate once. One world alive at a time, as in a
    real run; building and closing them is kept in ``setup_s`` and ``setup_cpu_s`` for
    the stages to take out. Ticks and times run on across runs, so answers never look
    older than their scan."""

    def __init__(self, workload: Workload) -> None:
        self.workload = workload
        self.setup_s = 0.0
        self.setup_cpu_s = 0.0
        self._frames = self._generate()

    def __iter__(self) -> Iterator[Frame]:
        return self._frames

    def __next__(self) -> Frame:
        return next(self._frames)

    def close(self) -> None:
        """Close the simulation still open, if the stream was not read to its end."""
        self._frames.close()

    def _timed(self, action: Callable[..., T], *args: object) -> T:
        wall, cpu = time.perf_counter(), time.process_time()
        try:
            return action(*args)
        finally:
            self.setup_s += time.perf_counter() - wall
            self.setup_cpu_s += time.process_time() - cpu

    def _generate(self) -> Generator[Frame, None, None]:
        from harness.sim.simulation import Simulation  # imports pybullet

        workload = self.workload
        tick0, t0 = 0, 0.0
        for scenario, profile in zip(workload.runs(), workload.profiles(), strict=True):
            seed = effective_seed(scenario, workload.settings)
            rng = np.random.default_rng(seed)
            sim: Simulation = self._timed(Simulation, scenario)
            try:
                tick = None
                for tick in sim.ticks():
                    t = t0 + tick.t
                    scan = profile.emit(tick.truth, sim.spec, rng, stamp=t)
                    yield Frame(tick0 + tick.tick, t, tick.x, tick.y, tick.yaw, scan)
                if tick is not None:
                    tick0 += tick.tick + 1
                    t0 += tick.t + sim.spec.scan_time
            finally:
                self._timed(sim.close)


@contextlib.contextmanager
def prepared_frames(workload: Workload) -> Iterator[FrameStream]:
    """The workload's frame stream; whatever simulation is still open is closed after."""
    stream = FrameStream(workload)
    try:
        yield stream
    finally:
        stream.close()
