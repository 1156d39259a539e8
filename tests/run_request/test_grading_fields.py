"""The grading file's run options are the run request's table's rows with a grading-file
field, read by the same readers and named by the field."""

from __future__ import annotations

from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.grading.grading_file import GradingFile, load_grading_file
from harness.run_request import OPTIONS


def test_the_files_run_options_are_the_tables() -> None:
    fields = set(GradingFile.model_fields)
    assert {row.grading for row in OPTIONS if row.grading} <= fields


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("seed: -1", "seed must be a whole number in 0..2**32-1, got -1"),
        ("seed: '7'", "seed must be a number, got '7'"),
        ("timeout: 0", "timeout must be a positive number, got 0"),
        ("ready_timeout: 1e9", "ready_timeout must be at most 86400"),
        ("warning_when_clear: always", "warning_when_clear: give optional or required"),
        ("link: pigeon", "link: unknown link 'pigeon' (known: "),
    ],
)
def test_a_bad_run_option_names_its_field(tmp_path: Path, text: str, says: str) -> None:
    path = tmp_path / "grading.yaml"
    path.write_text(f"scenarios: [approach_wall]\n{text}\n", encoding="utf-8")
    with pytest.raises(ConfigError) as caught:
        load_grading_file(path)
    assert str(caught.value) == f"--grading {path}: {says}" or says in str(caught.value)
    assert str(caught.value).startswith(f"--grading {path}: {says.split(' ')[0]}")


def test_the_files_values_are_request_values(tmp_path: Path) -> None:
    """By the request's keys (timeout is scan_timeout)."""
    path = tmp_path / "grading.yaml"
    path.write_text("scenarios: [a]\ntimeout: 2\nfaults: [noisy, dropouts]\n", encoding="utf-8")
    loaded = load_grading_file(path)
    assert loaded.request_values() == {"scan_timeout": 2.0, "faults": ["noisy", "dropouts"]}
