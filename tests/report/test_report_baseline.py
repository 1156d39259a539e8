"""Verdicts compared with a baseline summary.json: the pure comparison and its file checks."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from harness import __version__
from harness.errors import ConfigError
from harness.report.baseline import Baseline, compare, load_baseline, with_comparison
from harness.report.html import index_html
from harness.report.summary import run_summary


def entry(scenario: str, verdict: str = "PASS", **fields: Any) -> dict[str, Any]:
    """A summary.json scenario entry with the fields a comparison reads."""
    return {
        "scenario": scenario,
        "verdict": verdict,
        "ok": verdict == "PASS",
        "faults": "clean",
        "link": "ros2",
        "threshold": 0.5,
        "seed": 0,
        "total_s": 1.0,
        **fields,
    }


def baseline(*entries: dict[str, Any], harness: str = __version__) -> Baseline:
    return Baseline(path="base/summary.json", harness=harness, entries=entries)


def kinds(*entries: dict[str, Any], base: Baseline) -> list[str]:
    return [c.kind for c in compare(base, entries).changes]


def test_each_kind_of_change() -> None:
    """Passed then and fails now is a regression; the reverse is fixed; the rest as named."""
    base = baseline(entry("a"), entry("b", "FAIL"), entry("c", "ERROR"), entry("d"), entry("gone"))
    now = [entry("a", "FAIL"), entry("b"), entry("c", "FAIL"), entry("d"), entry("extra", "FAIL")]
    comparison = compare(base, now)
    assert [(c.kind, c.scenario, c.then, c.now) for c in comparison.changes] == [
        ("regressed", "a", "PASS", "FAIL"),
        ("fixed", "b", "FAIL", "PASS"),
        ("still failing", "c", "ERROR", "FAIL"),
        ("still passing", "d", "PASS", "PASS"),
        ("new", "extra", None, "FAIL"),
        ("missing", "gone", "PASS", None),
    ]
    assert comparison.counts["regressed"] == 1 and comparison.counts["missing"] == 1
    assert [c.scenario for c in comparison.unknown_failures] == ["a", "extra"]
    assert not comparison.ok
    assert comparison.notes == (
        "the baseline ran other scenarios: 1 new (extra [clean]); 1 not run now (gone [clean])",
    )


def test_known_failures_are_tolerated() -> None:
    """A node failing what it failed before, and nothing else, is ok against that baseline."""
    base = baseline(entry("a", "FAIL"), entry("b"))
    comparison = compare(base, [entry("a", "FAIL"), entry("b")])
    assert comparison.ok and comparison.notes == ()
    assert comparison.headline() == "0 regressed, 0 fixed, 1 still failing, 1 still passing"


def test_fault_profiles_and_repeats_are_matched_separately() -> None:
    """The key is scenario and fault profile; a scenario run twice is matched in order."""
    base = baseline(entry("a"), entry("a", faults="noisy", verdict="FAIL"), entry("a"))
    now = [entry("a"), entry("a", faults="noisy"), entry("a", "FAIL")]
    assert kinds(*now, base=base) == ["still passing", "fixed", "regressed"]


@pytest.mark.parametrize(
    ("field", "value", "reason"),
    [
        ("threshold", 0.4, "threshold 0.5 in the baseline, 0.4 now"),
        ("seed", 7, "seed 0 in the baseline, 7 now"),
        ("link", "inprocess", "link ros2 in the baseline, inprocess now"),
    ],
)
def test_judged_otherwise_is_named_not_compared(field: str, value: object, reason: str) -> None:
    """Another threshold, seed or link: named, never counted as fixed or still failing."""
    comparison = compare(baseline(entry("a", "FAIL")), [entry("a", "FAIL", **{field: value})])
    [change] = comparison.changes
    assert (change.kind, change.reason) == ("not compared", reason)
    assert not comparison.ok  # a failure nothing vouches for
    assert comparison.notes == (f"1 judged with another {field} in the baseline, so not compared",)


def test_another_warning_rule_is_not_compared_and_older_summaries_are_optional() -> None:
    """A summary written before the rule existed was judged 'optional'."""
    base = baseline(entry("a"), entry("b", warning_when_clear="optional"))
    now = [entry("a", "FAIL", warning_when_clear="required"), entry("b")]
    first, second = compare(base, now).changes
    assert first.kind == "not compared"
    assert first.reason == "warning_when_clear optional in the baseline, required now"
    assert second.kind == "still passing"


def test_threshold_compared_as_a_number() -> None:
    """0.5 written as 0.5000000000000001 by arithmetic is the same threshold."""
    assert kinds(entry("a", threshold=0.1 + 0.4), base=baseline(entry("a"))) == ["still passing"]


def test_other_harness_version_is_named() -> None:
    """A baseline from another version is compared, and says so."""
    comparison = compare(baseline(entry("a"), harness="0.0.9"), [entry("a")])
    assert comparison.ok
    assert comparison.notes[0].startswith(
        f"the baseline comes from fossbot-hil 0.0.9, this is {__version__}"
    )


def test_summary_and_page_carry_the_comparison() -> None:
    """summary.json gets each scenario's change and a `baseline` object; the page shows both."""
    summary = run_summary([entry("a", "FAIL", files={}, link="ros2"), entry("b", files={})])
    for e in summary["scenarios"]:
        e.update(ticks=1, failed=0, first_failure=None, error=None)
    comparison = compare(baseline(entry("a"), entry("b")), summary["scenarios"])
    data = with_comparison(summary, comparison)
    assert [e["change"] for e in data["scenarios"]] == ["regressed", "still passing"]
    assert data["baseline"]["ok"] is False and data["baseline"]["counts"]["regressed"] == 1
    assert data["baseline"]["changes"][0] == {
        "change": "regressed",
        "scenario": "a",
        "faults": "clean",
        "then": "PASS",
        "now": "FAIL",
        "reason": None,
    }
    json.dumps(data, allow_nan=False)
    page = index_html(data).decode()
    assert "<th>vs baseline" in page and "Compared with the baseline" in page
    assert '<span class="regressed">regressed</span>' in page


def write(path: Path, data: object) -> str:
    path.write_text(json.dumps(data) if not isinstance(data, str) else data)
    return str(path)


def test_load_reads_a_summary_or_its_folder(tmp_path: Path) -> None:
    """A summary.json, or the --out folder holding one."""
    write(tmp_path / "summary.json", {"harness": "0.1.0", "scenarios": [entry("a")]})
    for given in (tmp_path / "summary.json", tmp_path):
        loaded = load_baseline(str(given))
        assert loaded.harness == "0.1.0" and [e["scenario"] for e in loaded.entries] == ["a"]


def test_folder_without_summary_is_named(tmp_path: Path) -> None:
    """A folder given as the baseline, but not a report folder: said so, on one line."""
    with pytest.raises(ConfigError, match=r"^--baseline \S+: a folder without summary\.json$"):
        load_baseline(str(tmp_path))


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "no such file"),
        ("{not json", r"not JSON \(Expecting property name"),
        ([1, 2], r"not a fossbot-hil summary\.json \(no list of scenarios\)"),
        ({"scenarios": ["x"]}, r"scenarios\[0\] is not an object"),
        ({"scenarios": [{"scenario": "a"}]}, r"scenarios\[0\]\.verdict is missing or malformed"),
        ({"scenarios": [entry("a", seed=True)]}, r"scenarios\[0\]\.seed is missing or malformed"),
        ({"scenarios": [entry("a", verdict="MAYBE")]}, "verdict 'MAYBE' is unknown"),
        ("\xff\xfe", "cannot read it|not JSON"),
        ("[" * 100_000 + "]" * 100_000, r"not JSON this harness reads \(maximum recursion"),
        ('{"scenarios": [], "n": ' + "9" * 5000 + "}", r"not JSON this harness reads \(Exceeds"),
        ({"harness": 1, "scenarios": []}, r"summary\.json \(harness is malformed\)"),
    ],
)
def test_bad_baseline_is_one_line(tmp_path: Path, content: object, message: str) -> None:
    """Missing or malformed: a ConfigError naming the file, on one line."""
    path = tmp_path / "summary.json"
    if isinstance(content, str) and content.startswith("\xff"):
        path.write_bytes(b"\xff\xfe\x00")
    elif content is not None:
        write(path, content)
    with pytest.raises(ConfigError, match=message) as caught:
        load_baseline(str(path))
    assert str(caught.value).startswith(f"--baseline {path}: ") and "\n" not in str(caught.value)


def test_comparison_is_pure() -> None:
    """The comparison imports neither rclpy nor pybullet (nor matplotlib): CI tools can use it."""
    code = (
        "import sys, harness.report.baseline; "
        "print(sorted({'rclpy', 'pybullet', 'matplotlib'} & set(sys.modules)))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.stdout.strip() == "[]", done.stderr
