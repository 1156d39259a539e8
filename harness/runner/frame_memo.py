"""The frames of a plan simulated once in a process that judges the same plans again.

A grading judge runs the class's scenarios for one student after another. The
robot's motion is scripted and a plan's faults are seeded, so what the node is
sent never depends on the node: the second student's frames are the first's. A
process that knows it repeats plans (``remember_frames``) keeps each plan's
frames once its simulation has run to the end (the rest simulated for a run that
ended early), and later runs of that plan are given them instead of a new world.
Kept frames' arrays are read-only, so nothing downstream can change what the next
run is sent. A process can hand what it kept to others (``save_frames``,
``load_frames``): ``grade`` simulates the class's scenarios once for their tick
counts, and its judges start from those frames instead of each building the worlds.
"""

from __future__ import annotations

import pickle
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from harness.atomic_write import write_atomically

if TYPE_CHECKING:
    from harness.runner.frames import Frame
    from harness.runner.plan import RunPlan
    from harness.scenario.schema import Scenario

__all__ = [
    "MAX_FRAMES", "complete", "frames_of", "keeping", "load_frames", "remember_frames",
    "save_frames",
]  # fmt: skip

MAX_FRAMES = 10_000  # kept at most (a frame is about 3 KB): the default suite has 544

_kept: dict[tuple[object, ...], tuple[object, list[Frame]]] | None = None  # None: not kept


def remember_frames(enabled: bool = True) -> None:
    """From now on (or no longer) keep each plan's frames for its next run here."""
    global _kept
    _kept = {} if enabled else None


def _key(plan: RunPlan) -> tuple[object, ...] | None:
    if _kept is None or plan.settings.gui:  # a viewer shows the world: it must be built
        return None
    key = _key_of(plan.scenario, plan.seed, plan.profile)
    try:
        hash(key)
    except TypeError:  # a fault given values that cannot be compared: simulated each time
        return None
    return key


def _key_of(scenario: object, seed: object, profile: object) -> tuple[object, ...]:
    """Where a plan's frames are kept: its scenario object (held beside them, so its id
    stays its own), its seed and its faults."""
    return (id(scenario), seed, profile)


def frames_of(plan: RunPlan) -> list[Frame] | None:
    """The plan's frames, if a run of it here simulated them all."""
    key = _key(plan)
    kept = _kept.get(key) if key is not None and _kept is not None else None
    return kept[1] if kept is not None and kept[0] is plan.scenario else None


def keeping(plan: RunPlan, frames: Iterable[Frame]) -> Iterator[Frame]:
    """`frames` as they come, read-only, and kept for the plan's next run once all came
    (`complete` simulates the rest of a run that stopped early)."""
    key = _key(plan)
    if key is None:
        yield from frames
        return
    seen: list[Frame] = []
    for frame in frames:
        _read_only(frame)
        seen.append(frame)
        yield frame
    if _room_for(len(seen)):
        _kept[key] = (plan.scenario, seen)  # the scenario held: its id stays its own


def complete(kept: Iterator[Frame]) -> None:
    """Where frames are kept: draw the rest of `kept` (what `keeping` gave a run that ended
    before its last frame: its node broke, or its first failure ended it), so the plan's
    next run here is given them all instead of a world of its own."""
    if _kept is not None:
        for _ in kept:
            pass


def _room_for(count: int) -> bool:
    """Whether `count` more frames may be kept (MAX_FRAMES); False when none are kept."""
    return _kept is not None and sum(len(f) for _, f in _kept.values()) + count <= MAX_FRAMES


def _read_only(frame: Frame) -> None:
    frame.scan.ranges.flags.writeable = False
    frame.scan.intensities.flags.writeable = False


def _ref(scenario: Scenario) -> str:
    return scenario.source or scenario.name


def save_frames(path: Path) -> bool:
    """What is kept here, written to `path` (atomically) for other processes to start from;
    False if nothing is kept. A pickle: only for a folder no student can write."""
    if not _kept:
        return False
    plans = [(_ref(s), s, key[1], key[2], frames) for key, (s, frames) in _kept.items()]
    write_atomically(path, pickle.dumps(plans, protocol=pickle.HIGHEST_PROTOCOL))
    return True


def load_frames(path: Path, scenarios: Iterable[Scenario]) -> int:
    """The frames `save_frames` wrote, kept here for `scenarios` (those of the same file and
    contents, seed and faults as they were simulated with): how many plans. A file that
    cannot be read gives none; what it lacks is simulated as before."""
    if _kept is None:
        return 0
    try:
        plans = pickle.loads(path.read_bytes())
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ValueError):
        return 0
    ours = {_ref(s): s for s in scenarios}
    given = 0
    for ref, simulated, seed, profile, frames in plans:
        scenario = ours.get(ref)
        if scenario is None or scenario != simulated:
            continue
        if not _room_for(len(frames)):
            break
        for frame in frames:
            _read_only(frame)
        _kept[_key_of(scenario, seed, profile)] = (scenario, frames)
        given += 1
    return given
