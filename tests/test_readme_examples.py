"""The README's examples are real: its first command runs as written, and each output it
shows is what a real run prints.

Every code block without a language in README.md is output, marked by the comment
line above it (``<!-- output: NAME -->``); NAME is a run below, real commands over
ROS 2 with real nodes. Each shown line must be a line of that run's output, in order
and consecutive; a ``...`` line stands for any lines; the time column of a table
(which varies) is matched as any number. Drift in what the harness prints, or an
example edited by hand, fails here.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from command_line import COMMAND

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
STUDENT_NODE = ROOT / "tests" / "ros" / "student_node.py"
MARKER = re.compile(r"<!-- output: ([\w-]+) -->")
TABLE_TIME = re.compile(r"\d+\.\d\d$")  # a table row's last column: seconds, never equal twice


@dataclass(frozen=True)
class Shown:
    """One output block of the README: the run that prints it and its lines."""

    name: str
    line: int  # of its opening fence, for messages
    lines: tuple[str, ...]


def output_blocks(text: str) -> list[Shown]:
    """Each code block without a language, named by the marker on the line above it
    ("" when there is none)."""
    lines = text.splitlines()
    blocks: list[Shown] = []
    i = 0
    while i < len(lines):
        if not lines[i].startswith("```"):
            i += 1
            continue
        language = lines[i][3:].strip()
        end = lines.index("```", i + 1)
        if not language:
            marker = MARKER.fullmatch(lines[i - 1].strip()) if i else None
            name = marker[1] if marker else ""
            blocks.append(Shown(name, i + 1, tuple(lines[i + 1 : end])))
        i = end + 1
    return blocks


def line_pattern(shown: str, loose: re.Pattern[str] | None) -> re.Pattern[str]:
    """`shown` as a pattern: its `loose` part any number, a run of spaces any run (a
    column as wide as its widest value), everything else as written."""
    parts, at = [], 0
    for match in loose.finditer(shown) if loose else ():
        parts += [re.escape(shown[at : match.start()]), r"\d+(?:\.\d+)?"]
        at = match.end()
    parts.append(re.escape(shown[at:]))
    return re.compile(re.sub(r"(?:\\ ){2,}| {2,}", " +", "".join(parts)))


def mismatch(shown: Shown, output: str, loose: re.Pattern[str] | None) -> str | None:
    """None when `shown` is an excerpt of `output` (its segments between ``...`` lines
    consecutive, in order); else the first shown line that is not there."""
    real = output.splitlines()
    at = 0
    segments: list[list[str]] = [[]]
    for line in shown.lines:
        if line.strip() == "...":
            segments.append([])
        else:
            segments[-1].append(line)
    for segment in (s for s in segments if s):
        patterns = [line_pattern(line, loose) for line in segment]
        starts = range(at, len(real) - len(segment) + 1)
        found = next(
            (i for i in starts if all(p.fullmatch(real[i + k]) for k, p in enumerate(patterns))),
            None,
        )
        if found is None:
            return f"README.md line {shown.line} ({shown.name}): not in the output: {segment}"
        at = found + len(segment)
    return None


def run(args: list[str], cwd: Path, env: dict[str, str] | None = None) -> str:
    done = subprocess.run(
        args, cwd=cwd, env=env, capture_output=True, text=True, timeout=100, check=False
    )
    assert "Traceback" not in done.stderr, done.stderr
    return done.stdout


def student(path: Path, variant: str) -> Path:
    """The test suite's student node as one script, made to run `variant`."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"import sys\n\nsys.argv[1:1] = [{variant!r}]\n" + STUDENT_NODE.read_text())
    return path


def with_home(home: Path) -> dict[str, str]:
    """This environment with `home` as $HOME, and this Python's scripts (fossbot-hil)
    first on PATH, as in the activated virtual environment the README assumes."""
    path = f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"
    return {**os.environ, "HOME": str(home), "PATH": path}


def run_all(tmp: Path) -> str:
    """`fossbot-hil run`: every shipped scenario against the reference node."""
    return run([*COMMAND, "run"], tmp)


def node_line(tmp: Path) -> str:
    """`--node "python3 my_node.py"` (a student's script, in the working folder)."""
    student(tmp / "my_node.py", "correct")
    return run([*COMMAND, "run", "obstacle_at_side", "--node", "python3 my_node.py"], tmp)


def failure(tmp: Path) -> str:
    """rotate_beside_wall against ~/lab07/fossbot_lidar_node.py reporting degrees."""
    student(tmp / "lab07" / "fossbot_lidar_node.py", "angle_in_degrees")
    node = ["--node", "python3 ~/lab07/fossbot_lidar_node.py"]
    return run([*COMMAND, "run", "rotate_beside_wall", *node], tmp, with_home(tmp))


RUNS: dict[str, tuple[Callable[[Path], str], re.Pattern[str] | None]] = {
    "run": (run_all, TABLE_TIME),
    "node-line": (node_line, None),
    "failure": (failure, None),
}


def test_every_output_block_names_a_run_here() -> None:
    """An output block no run below checks is an example that may drift (a block that is
    not output names its language: ```sh, ```text)."""
    blocks = output_blocks(README.read_text(encoding="utf-8"))
    unmarked = [b.line for b in blocks if b.name not in RUNS]
    assert not unmarked, f"README.md lines {unmarked}: output blocks need <!-- output: NAME -->"
    assert sorted(b.name for b in blocks) == sorted(RUNS)


@pytest.mark.parametrize(
    "block", output_blocks(README.read_text(encoding="utf-8")), ids=lambda b: b.name or b.line
)
def test_each_shown_output_is_what_a_real_run_prints(block: Shown, tmp_path: Path) -> None:
    assert block.name in RUNS, f"README.md line {block.line}: no <!-- output: NAME --> above"
    produce, loose = RUNS[block.name]
    output = produce(tmp_path)
    problem = mismatch(block, output, loose)
    assert problem is None, f"{problem}\nthe real output:\n{output}"


def test_the_first_node_example_runs_as_written(tmp_path: Path) -> None:
    """The README's `fossbot-hil run --node "python3 ~/lab07/fossbot_lidar_node.py"`,
    given to a shell verbatim, with a correct node in ~/lab07: every scenario passes."""
    text = README.read_text(encoding="utf-8")
    command = next(line for line in text.splitlines() if "--node" in line and "~/lab07" in line)
    assert shlex.split(command)[:3] == ["fossbot-hil", "run", "--node"], command
    student(tmp_path / "lab07" / "fossbot_lidar_node.py", "correct")
    done = subprocess.run(
        ["sh", "-c", command],
        cwd=tmp_path,
        env=with_home(tmp_path),
        capture_output=True,
        text=True,
        timeout=100,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "7 of 7 scenarios passed" in done.stdout
    assert f"node: python3 {tmp_path}/lab07/fossbot_lidar_node.py" in done.stdout


def test_a_shown_line_that_differs_is_found() -> None:
    """The check itself: a changed word, a lost line, lines out of order are all caught;
    a time that differs is not."""
    output = "a  1.25\nb  2.50\n\nc\nd"
    shown = Shown("x", 1, ("a  9.99", "...", "c", "d"))
    assert mismatch(shown, output, TABLE_TIME) is None
    for lines in (("a  1.25", "b  2.51"), ("a 1.25", "...", "e"), ("c", "...", "a  1.25")):
        assert mismatch(Shown("x", 1, lines), output, None) is not None
    assert mismatch(Shown("x", 1, ("b  2.50", "c")), output, None) is not None  # the blank
