"""explain(): which factors a campaign's failures depend on, from rows as csv gives them."""

from __future__ import annotations

import csv
import io
import random
from collections.abc import Callable
from itertools import product

from harness.campaign.factors import FACTORS, explain

SCENARIOS = ("corridor", "wall_ahead")
FAULTS = ("none", "drifting_rate", "noisy,late")
THRESHOLDS = ("0.1", "0.2", "0.3", "0.5")
SEEDS = ("1", "2")

Fails = Callable[[str, str, str, str], str | bool]


def table(
    fails: Fails,
    scenarios: tuple[str, ...] = SCENARIOS,
    faults: tuple[str, ...] = FAULTS,
    thresholds: tuple[str, ...] = THRESHOLDS,
    seeds: tuple[str, ...] = SEEDS,
) -> list[dict[str, str]]:
    """Every combination, written to CSV and read back so every value is a string.
    `fails` returns False (PASS), True (FAIL) or a verdict string."""
    out = io.StringIO()
    fields = ["scenario", "faults", "seed", "threshold", "verdict", "duration_s", "node"]
    writer = csv.DictWriter(out, fields)
    writer.writeheader()
    for s, f, t, d in product(scenarios, faults, thresholds, seeds):
        verdict = fails(s, f, t, d)
        verdict = verdict if isinstance(verdict, str) else ("FAIL" if verdict else "PASS")
        row = dict(scenario=s, faults=f, seed=d, threshold=t, verdict=verdict)
        writer.writerow({**row, "duration_s": "1.5", "node": "student_7"})
    return list(csv.DictReader(io.StringIO(out.getvalue())))


def test_factors_are_the_public_tuple() -> None:
    assert FACTORS == ("scenario", "faults", "threshold", "seed")


def test_no_runs() -> None:
    assert explain([]) == ["no runs: nothing to explain"]


def test_no_failures_says_all_passed() -> None:
    lines = explain(table(lambda *_: False))
    assert lines == ["all 48 runs passed"]


def test_a_single_run() -> None:
    row = {"scenario": "corridor", "faults": "", "seed": "3", "threshold": "", "verdict": "PASS"}
    assert explain([row]) == ["the 1 run passed"]
    (line,) = explain([{**row, "verdict": "ERROR"}])
    assert "1 of 1 run failed (0 FAIL, 1 ERROR)" in line
    assert "cannot be tied to a factor" in line


def test_repeated_identical_runs_have_no_factor_to_blame() -> None:
    row = {"scenario": "corridor", "faults": "none", "seed": "3", "threshold": "0.3"}
    rows = [{**row, "verdict": v} for v in ("PASS", "FAIL", "PASS")]
    (line,) = explain(rows)
    assert "1 of 3 runs failed" in line
    assert "no factor varies across the 3 runs" in line


def test_failures_confined_to_one_fault_profile() -> None:
    rows = table(lambda s, f, t, d: f == "drifting_rate" and (t != "0.5" or d == "1"))
    lines = explain(rows)
    assert lines[0] == (
        "fails only with faults drifting_rate: 14 of 16 runs there failed, 0 of 32 elsewhere"
    )
    assert "14 of 48 runs failed" in lines
    rates = next(line for line in lines if line.startswith("faults,"))
    assert "drifting_rate 14/16" in rates and "none 0/16" in rates
    assert '"noisy,late" 0/16' in rates
    assert not any("every level of every factor" in line for line in lines)


def test_errors_count_as_failures_and_are_named_apart() -> None:
    def fails(s: str, f: str, t: str, d: str) -> str | bool:
        if f != "drifting_rate":
            return False
        return "ERROR" if (s, d) == ("corridor", "1") else True

    lines = explain(table(fails))
    assert lines[0].startswith("fails only with faults drifting_rate: ")
    assert "16 of 16 runs there failed (12 FAIL, 4 ERROR), 0 of 32 elsewhere" in lines[0]
    assert "16 of 48 runs failed (12 FAIL, 4 ERROR)" in lines
    assert any("drifting_rate 16/16 (4 ERROR)" in line for line in lines)


def test_odd_verdicts_are_errors_and_case_does_not_matter() -> None:
    rows = table(lambda s, f, t, d: s == "wall_ahead" and ("timeout" if d == "1" else "fail"))
    for row in rows:
        row["verdict"] = row["verdict"].lower()
    lines = explain(rows)
    assert "fails only with scenario wall_ahead" in lines[0]
    assert "24 of 24 runs there failed (12 FAIL, 12 ERROR), 0 of 24 elsewhere" in lines[0]


def test_low_thresholds_fail_as_an_ordered_range() -> None:
    lines = explain(table(lambda s, f, t, d: float(t) < 0.3))
    assert lines[0].startswith("fails only when threshold <= 0.2 (every run from 0.3 up passed)")
    assert "24 of 24 runs there failed, 0 of 24 elsewhere" in lines[0]
    assert any(
        "threshold, runs failed per level: 0.1 12/12, 0.2 12/12, 0.3 0/12" in x for x in lines
    )


def test_high_thresholds_fail_as_an_ordered_range() -> None:
    lines = explain(table(lambda s, f, t, d: float(t) >= 0.3 and d == "2"))
    assert any("fails only when threshold >= 0.3 (every run up to 0.2 passed)" in x for x in lines)
    assert any("12 of 24 runs there failed, 0 of 24 elsewhere" in x for x in lines)


def test_thresholds_in_the_middle_are_levels_not_a_range() -> None:
    lines = explain(table(lambda s, f, t, d: t == "0.2"))
    assert lines[0].startswith("fails only with threshold 0.2: 12 of 12 runs there failed")
    assert not any("<=" in line or ">=" in line for line in lines)


def test_thresholds_written_differently_are_one_level() -> None:
    rows = table(lambda s, f, t, d: float(t) < 0.3)
    for row in rows:
        row["threshold"] = {"0.3": "0.30", "0.1": ".1"}.get(row["threshold"], row["threshold"])
    assert explain(rows)[0].startswith("fails only when threshold <= 0.2 ")


def test_empty_threshold_is_the_scenarios_own_and_stays_out_of_ranges() -> None:
    thresholds = ("", "0.1", "0.3")
    passing_own = explain(table(lambda s, f, t, d: t == "0.1", thresholds=thresholds))
    assert passing_own[0].startswith("fails only when threshold <= 0.1 (every run from 0.3 up")
    assert "12 of 12 runs there failed, 0 of 24 elsewhere" in passing_own[0]
    failing_own = explain(table(lambda s, f, t, d: t != "0.3", thresholds=thresholds))
    assert failing_own[0].startswith("fails only with thresholds (scenario's own) or 0.1: ")
    assert "24 of 24 runs there failed, 0 of 12 elsewhere" in failing_own[0]


def test_two_factors_together_when_neither_alone_says_it() -> None:
    lines = explain(table(lambda s, f, t, d: f == "drifting_rate" and float(t) < 0.3))
    assert lines[0] == (
        "fails only with faults drifting_rate and threshold <= 0.2: "
        "8 of 8 runs there failed, 0 of 40 elsewhere"
    )
    # the single factors follow, with their weaker rates
    assert lines[1].startswith("fails only with faults drifting_rate: 8 of 16 runs there failed")
    assert lines[2].startswith("fails only when threshold <= 0.2 (every run from 0.3 up passed)")


def test_combinations_when_every_level_of_each_factor_fails_somewhere() -> None:
    lines = explain(table(lambda s, f, t, d: (s == "corridor") == (f == "drifting_rate")))
    assert lines[0].startswith("fails only in 3 of 6 combinations of scenario and faults (")
    assert "scenario corridor with faults drifting_rate" in lines[0]
    assert "scenario wall_ahead with faults none" in lines[0]
    assert lines[0].endswith("24 of 24 runs there failed, 0 of 24 elsewhere")
    assert "fails at every level of every factor (24 of 48 runs): not tied to one factor" in lines


def test_failures_at_every_level_of_every_factor() -> None:
    rng = random.Random(4)
    outcome = {combo: rng.random() < 0.5 for combo in product(SCENARIOS, FAULTS, THRESHOLDS)}
    outcome[("corridor", "none", "0.1")] = outcome[("wall_ahead", "noisy,late", "0.5")] = True
    lines = explain(table(lambda s, f, t, d: outcome[(s, f, t)] == (d == "1")))
    assert (
        lines[0] == "fails at every level of every factor (24 of 48 runs): not tied to one factor"
    )
    assert lines[1] == "24 of 48 runs failed"
    assert "seed: failures with every seed (2 seeds)" in lines


def test_every_run_failing() -> None:
    lines = explain(table(lambda *_: "ERROR"))
    assert (
        lines[0] == "fails at every level of every factor (48 of 48 runs): not tied to one factor"
    )
    assert lines[1] == "48 of 48 runs failed (0 FAIL, 48 ERROR)"


def test_seeds_say_some_or_every_never_a_range() -> None:
    seeds = tuple(str(n) for n in range(1, 9))
    lines = explain(table(lambda s, f, t, d: int(d) <= 3, seeds=seeds))
    assert lines[0].startswith("fails only with some seeds (3 of 8: 1, 2 or 3): ")
    assert "seed: failures with some seeds (3 of 8: 1, 2 or 3)" in lines
    assert not any("seed <" in line or "seed >" in line for line in lines)


def test_many_levels_stay_short() -> None:
    scenarios = tuple(f"room_{n:02d}" for n in range(12))
    faults = tuple(f"profile_{n}" for n in range(9))
    lines = explain(
        table(lambda s, f, t, d: s == "room_07" and f != "profile_3", scenarios, faults)
    )
    assert len(lines) <= 10
    assert lines[0] == (
        "fails only with scenario room_07 and faults profile_0, profile_1, profile_2, "
        "profile_4 or 4 more: 64 of 64 runs there failed, 0 of 800 elsewhere"
    )
    assert "fails only with scenario room_07: 64 of 72 runs there failed" in lines[1]
    rates = next(line for line in lines if line.startswith("scenario,"))
    assert rates.startswith("scenario, runs failed per level: room_07 64/72, room_00 0/72")
    assert rates.endswith("7 more levels 0/504")


def test_faults_lists_are_one_level_whatever_the_spacing() -> None:
    rows = table(lambda s, f, t, d: f == "noisy,late")
    for i, row in enumerate(rows):
        if row["faults"] == "noisy,late" and i % 2:
            row["faults"] = " noisy , late "
    assert explain(rows)[0] == (
        'fails only with faults "noisy,late": 16 of 16 runs there failed, 0 of 32 elsewhere'
    )


def test_typed_values_and_missing_keys_are_read_too() -> None:
    rows: list[dict[str, str | int | float | None]] = [
        {"scenario": "corridor", "faults": None, "seed": 1, "threshold": 0.1, "verdict": "FAIL"},
        {"scenario": "corridor", "faults": None, "seed": 2.0, "threshold": 0.1, "verdict": "FAIL"},
        {"scenario": "corridor", "seed": 1, "threshold": 0.4, "verdict": "PASS"},
        {"scenario": "corridor", "seed": 2, "threshold": None, "verdict": "PASS"},
    ]
    lines = explain(rows)
    assert lines[0].startswith("fails only when threshold <= 0.1 (every run from 0.4 up passed)")
    assert "2 of 2 runs there failed, 0 of 2 elsewhere" in lines[0]


def test_order_of_rows_does_not_matter() -> None:
    rows = table(lambda s, f, t, d: f == "drifting_rate" and float(t) < 0.3 or s == "x")
    shuffled = rows[:]
    random.Random(1).shuffle(shuffled)
    assert explain(shuffled) == explain(rows)


def test_a_generated_variation_is_a_factor_ordered_like_the_threshold() -> None:
    """`--vary wall_distance=...`: 'fails only when wall_distance <= 0.3', named as such."""
    rows = []
    for distance, row in product(("0.2", "0.3", "1", "2"), table(lambda s, f, t, d: False)):
        failed = float(distance) <= 0.3 and row["faults"] == "drifting_rate"
        rows.append({**row, "wall_distance": distance, "verdict": "FAIL" if failed else "PASS"})
    lines = explain(rows, varied=["wall_distance"])
    assert any("when wall_distance <= 0.3" in line for line in lines), lines
    assert any(line.startswith("wall_distance, runs failed per level: 0.2 ") for line in lines)
    assert explain(rows) == explain([{**r, "wall_distance": "x"} for r in rows])  # not asked
