"""`grade` says which typical mistakes its scenarios let pass (harness.audit): the audit
runs once, after the class, on the class's cluster, and is kept in the user's cache, so
the next grade of the same scenarios warns at once."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
from pathlib import Path

import pytest
from command_line import COMMAND
from grading_class import script_student
from short_scenarios import WALL_AHEAD

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(300)]


def grade(tmp_path: Path, scenario: Path, out: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*COMMAND, "grade", str(tmp_path / "class"), "--scenario", str(scenario)]
        + ["--workers", "1", "--out", str(tmp_path / out)],
        capture_output=True,
        text=True,
        timeout=280,
        env={**os.environ, "FOSSBOT_HIL_CACHE_DIR": str(tmp_path / "cache")},
    )


def test_grade_warns_naming_the_mistakes_its_scenarios_let_pass(tmp_path: Path) -> None:
    """An approach to a wall alone never shows an empty scan nor a warning that must
    clear: the warning names those mistakes, and the scenario file to audit, on the
    terminal and on grades.html; the second grade takes it from the cache."""
    script_student(tmp_path / "class" / "dave")
    scenario = tmp_path / "wall_ahead.yaml"
    scenario.write_text(WALL_AHEAD)
    first = grade(tmp_path, scenario, "grades")
    assert first.returncode == 0, first.stdout + first.stderr
    warning = first.stdout.strip().splitlines()[-1]
    assert warning.startswith("warning: these scenarios let "), first.stdout
    for name in ("warning_latched", "silent_when_clear", "crash_when_nothing_in_range"):
        assert name in warning, warning
    words = shlex.quote(str(scenario.resolve()))  # a file, not a shipped name
    assert f"fossbot-hil audit {words} shows what would catch them" in warning
    page = (tmp_path / "grades" / "grades.html").read_text(encoding="utf-8")
    assert '<p class="audit">warning: these scenarios let ' in page  # the class page says it too
    audit = json.loads((tmp_path / "grades" / "audit.json").read_text())
    assert "warning_latched" in audit["survivors"]
    assert "angle_in_degrees" not in audit["survivors"]  # an approach catches that one
    again = grade(tmp_path, scenario, "grades_again")
    assert again.returncode == 0, again.stdout + again.stderr
    assert again.stdout.strip().splitlines()[-1] == warning
    assert not (tmp_path / "grades_again" / "audit").exists(), "audited again, not cached"
