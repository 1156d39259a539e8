"""The catalogue of typical Lab 07 mistakes ("mutants") the audit runs (pure).

Each is one mistake made on an otherwise correct node (``mutant_node.py``,
the mistake chosen by its first argument; ``mutant_command``). A suite
worth its salt fails every mutant somewhere; ``CONTROL`` must pass.
"""

from __future__ import annotations

import shlex
import sys
from dataclasses import dataclass
from pathlib import Path

from harness.errors import ConfigError

__all__ = ["CONTROL", "MUTANTS", "NODE_SCRIPT", "Mutant", "mutant_command", "mutant_named"]

NODE_SCRIPT = Path(__file__).resolve().with_name("mutant_node.py")
CONTROL = "correct"  # the node without a mistake, written the same way: the audit's sanity check
QUICK_S = 0.27  # a scenario of a mistake that shows in its answers: a node start, a few ticks


@dataclass(frozen=True)
class Mutant:
    """One typical mistake, made on an otherwise correct node."""

    name: str  # snake_case; the name in the CLI, the kill matrix and --json
    mistake: str  # one line: what the node does wrong, in a student's terms
    caught_by: str  # one line: the kind of scenario that kills it (options as {key})
    # Seconds a scenario of its suite takes, measured with the shipped suite on 2 busy
    # cores, each scenario ended at its first failed tick (what batches balance): a
    # mistake whose runs wait out deadlines costs many quick ones, and goes first.
    cost_s: float = QUICK_S


MUTANTS: tuple[Mutant, ...] = (
    # -- the angle of the nearest return (an index off by one is no mistake to the
    # oracle: it accepts an angle one beam either way, so it is not in the library)
    Mutant(
        "angle_in_degrees",
        "reports the angle in degrees (math.degrees) where the lab asks for radians",
        "any scan whose nearest return is not straight ahead",
    ),
    Mutant(
        "angle_without_angle_min",
        "computes the angle as index * angle_increment, forgetting angle_min",
        "a scan whose angle_min is not 0 (Gazebo-like, -pi..pi)",
    ),
    Mutant(
        "angle_from_filtered_index",
        "takes the index of the minimum in the list of valid readings, not in msg.ranges",
        "invalid readings (inf, NaN, 0) at lower indices than the nearest return",
    ),
    Mutant(
        "angle_from_wrong_end",
        "counts beams from angle_max down (angle_max - index * angle_increment)",
        "a nearest return away from the scan's axis of symmetry (at the side)",
    ),
    # -- which readings count (REP-117)
    Mutant(
        "min_over_raw_ranges",
        "takes min(msg.ranges) with no filtering at all (the lab's own pitfall)",
        "a scan with nothing in range: every beam +inf",
    ),
    Mutant(
        "only_inf_filtered",
        "drops only +inf (r != inf), so -inf, NaN, 0.0 and out-of-limit readings count",
        "a scan with -inf (closer than range_min), 0.0 or NaN readings",
    ),
    Mutant(
        "nan_not_filtered",
        "filters +-inf and the range limits with comparisons that let NaN through",
        "a scan with a NaN beside valid returns (NaN dropouts of a wall in range)",
    ),
    Mutant(
        "zero_as_obstacle",
        "has no range_min check: 0.0 (no return) and ghosts below range_min count",
        "a driver that writes 0.0 for no return, or ghost returns below range_min",
    ),
    Mutant(
        "below_range_min_kept",
        "drops 0.0 with r > 0 instead of r >= range_min: ghosts below range_min count",
        "ghost returns between 0 and range_min",
    ),
    Mutant(
        "above_range_max_kept",
        "has no range_max check: finite readings beyond range_max count",
        "a finite reading above range_max (a driver that passes raw distances through)",
    ),
    Mutant(
        "front_sector_only",
        "looks only at the beams within 30 degrees of straight ahead",
        "an obstacle at the side or behind",
    ),
    # -- the warning
    Mutant(
        "threshold_hard_coded",
        "ignores the threshold parameter and warns below the lab's 0.5 m",
        "a threshold other than 0.5 m, with the nearest return between the two",
    ),
    Mutant(
        "warning_inverted",
        "publishes True when the way is clear and False when an obstacle is close",
        "any scan",
    ),
    Mutant(
        "warning_latched",
        "once the warning is True it stays True for ever",
        "an obstacle closer than the threshold that then moves away",
    ),
    Mutant(
        "warning_never",
        "creates the Bool publisher but never publishes the warning",
        "an obstacle closer than the threshold",
    ),
    Mutant(
        "rounded_before_comparing",
        "rounds the distance to 0.1 m, then compares the rounded value with the threshold",
        "a nearest return just below the threshold (within 0.05 m)",
    ),
    # -- when and how it answers
    Mutant(
        "one_scan_late",
        "publishes the previous scan's answer (status and Bool), nothing for the first",
        "a robot that moves: consecutive scans differ",
        cost_s=1.8,  # its first scan goes twice: unanswered, then answered late
    ),
    Mutant(
        "silent_when_clear",
        "publishes no status and no Bool when nothing valid is in range",
        "a scan with nothing in range",
        cost_s=3.7,  # the readiness bound (20 s) where its first scan is clear
    ),
    Mutant(
        "status_only_on_change",
        "publishes the status only when its text changed (the Bool every scan)",
        "two consecutive scans with the same answer (standing still, nothing in range)",
        cost_s=2.1,  # a deadline and its catch-up (1 s + 3 s) where a status repeats
    ),
    Mutant("status_twice", "publishes the status String twice for every scan", "any scan"),
    Mutant(
        "crash_when_nothing_in_range",
        "takes the minimum of an empty list when nothing is valid: the node dies",
        "a scan with nothing in range",
    ),
    Mutant(
        "slow_callback",
        "takes 1.5 s per scan before answering",
        "any run: the answers miss the per-scan deadline",
        cost_s=6.0,  # its first scan answered two or three times over, 1.5 s each
    ),
    Mutant(
        "goes_silent",
        "stops answering after its 10th scan",
        "a run of more than 10 scans",
        cost_s=4.2,  # a deadline and its catch-up (1 s + 3 s) in every scenario
    ),
    # -- units and configuration
    Mutant(
        "centimetres",
        "reports the distance in centimetres where the lab asks for metres",
        "any scan with an obstacle in range",
    ),
    Mutant(
        "scan_topic_ignored",
        "subscribes to /scan whatever the lidar_topic parameter says",
        "a run with another scan topic ({params} lidar_topic:=... {scan_topic} ...)",
    ),
)

_BY_NAME = {mutant.name: mutant for mutant in MUTANTS}


def _known() -> str:
    return ", ".join(mutant.name for mutant in MUTANTS)


def mutant_named(name: str) -> Mutant:
    """The mutant called `name`; a ConfigError naming the known ones otherwise."""
    mutant = _BY_NAME.get(name)
    if mutant is None:
        control = f" ({CONTROL!r} is the control, not a mutant)" if name == CONTROL else ""
        raise ConfigError(f"unknown mutant {name!r}{control}; known: {_known()}")
    return mutant


def mutant_command(name: str, python: str = sys.executable) -> str:
    """The node command line the harness runs for mutant `name` (or the control,
    ``correct``): ``<python> <mutant_node.py> NAME``, each word shell-quoted."""
    if name != CONTROL:
        mutant_named(name)
    return shlex.join([python, str(NODE_SCRIPT), name])
