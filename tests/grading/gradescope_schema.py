"""Gradescope's documented results.json format, as a check (tests only).

From "Autograder Specifications" (gradescope-autograders.readthedocs.io/en/latest/specs/,
the docs/specs.md of github.com/gradescope/autograder_samples): the top-level keys and
each test's keys, which are optional, their types, and the values the visibility,
status and format fields take. A key the format does not have is an error here, so a
typo cannot pass for a field Gradescope would read.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

VISIBILITIES = {"hidden", "after_due_date", "after_published", "visible"}
FORMATS = {"text", "html", "simple_format", "md", "ansi"}
STATUSES = {"passed", "failed"}
TOP_KEYS = {
    "score": (int, float),
    "execution_time": (int, float),
    "output": str,
    "output_format": str,
    "test_output_format": str,
    "test_name_format": str,
    "visibility": str,
    "stdout_visibility": str,
    "extra_data": dict,
    "tests": list,
    "leaderboard": list,
}
TEST_KEYS = {
    "score": (int, float),
    "max_score": (int, float),
    "status": str,
    "name": str,
    "name_format": str,
    "number": str,
    "output": str,
    "output_format": str,
    "tags": list,
    "visibility": str,
    "extra_data": dict,
}


def _typed(where: str, data: dict[str, Any], keys: dict[str, Any]) -> None:
    unknown = set(data) - set(keys)
    assert not unknown, f"{where}: keys Gradescope does not document: {sorted(unknown)}"
    for key, kind in keys.items():
        if key in data:
            value = data[key]
            assert isinstance(value, kind) and not isinstance(value, bool), (
                f"{where}.{key}: {value!r} is not {kind}"
            )


def check_gradescope(data: Any) -> None:
    """AssertionError naming the first way `data` is not a results.json Gradescope takes."""
    assert isinstance(data, dict), "results.json must hold a JSON object"
    _typed("results", data, TOP_KEYS)
    tests = data.get("tests", [])
    assert "score" in data or (tests and all("score" in t for t in tests)), (
        "a top-level score, or a score on every test, is required"
    )
    for key in ("visibility", "stdout_visibility"):
        if key in data:
            assert data[key] in VISIBILITIES, f"results.{key}: {data[key]!r}"
    for key in ("output_format", "test_output_format", "test_name_format"):
        if key in data:
            assert data[key] in FORMATS, f"results.{key}: {data[key]!r}"
    if "execution_time" in data:
        assert data["execution_time"] >= 0, "execution_time is seconds"
    for i, test in enumerate(tests):
        where = f"tests[{i}]"
        assert isinstance(test, dict), f"{where}: not an object"
        _typed(where, test, TEST_KEYS)
        if "visibility" in test:
            assert test["visibility"] in VISIBILITIES, f"{where}.visibility: {test['visibility']}"
        if "status" in test:
            assert test["status"] in STATUSES, f"{where}.status: {test['status']!r}"
        for key in ("name_format", "output_format"):
            if key in test:
                assert test[key] in FORMATS, f"{where}.{key}: {test[key]!r}"
        if "tags" in test:
            assert all(isinstance(t, str) for t in test["tags"]), f"{where}.tags: strings"
        if "score" in test and "max_score" in test:
            assert 0 <= test["score"] <= test["max_score"] + 1e-9, f"{where}: score > max_score"


def read_results(path: Path) -> dict[str, Any]:
    """A results.json file, parsed and checked against the format."""
    data = json.loads(path.read_text(encoding="utf-8"))
    check_gradescope(data)
    return data
