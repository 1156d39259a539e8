"""Generated `fossbot-hil run` command lines: each one runs, or is refused in one line.

Hypothesis combines the options that take text: topics from a hostile
alphabet (empty, blank, control characters, '~', '{}', '//', NUL, an
undecodable byte), node parameters and the threshold parameter's name,
numbers as text (nan, inf, negative, huge), seeds, timeouts, domain ids,
--out and --junit-xml paths (empty, existing files and folders, paths
through a file, a FIFO), --link values and scenario names. Each command
line runs in this process through ``harness.cli.main`` over the inprocess
link, on a scenario of three ticks, so an accepted one takes milliseconds.

Whatever the input: the exit code is 0, 1 or 2; nothing prints a
traceback; exit 2 prints exactly one line on stderr, ``fossbot-hil:
error: ...``; no process is left running; and no half-written file (a
writer's hidden temporary) is left in the working folder. Deterministic
(derandomized, no example database) so CI sees the same command lines.
"""

from __future__ import annotations

import json
import os
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import pytest
from hostile_checks import run_in_process
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from property_depth import examples

from harness.atomic_write import TEMPORARY_NAME
from harness.report.folder_lock import LOCK_NAME

pytestmark = [pytest.mark.timeout(300), pytest.mark.slow]

# Each option's hostile values are also refused one by one through the real command
# (test_hostile_input.py's test_hostile_option); here they are mixed.
EXAMPLES = examples(60)
TINY = """\
description: Three ticks beside a wall.
obstacles:
  - {type: wall, start: [1.0, -1.0], end: [1.0, 1.0]}
motion:
  segments:
    - until: {duration: 0.2}
"""

HOSTILE = st.text(alphabet="ab/_~{}0 9.-:=*\t\n\x1b\x00\x7f\u00e9\u202e", max_size=12)


@dataclass(frozen=True)
class Values:
    """An option's values: ones that should work, ones that cannot, and fuzz that may."""

    good: st.SearchStrategy[str]
    bad: st.SearchStrategy[str]  # each of these must be refused (exit 2)
    fuzz: st.SearchStrategy[str] = st.nothing()


TOPICS = Values(
    st.sampled_from(["/robot/scan", "scan_in", "/status2", "warn", "/a/b_c"]),
    st.sampled_from(["", " ", "/a//b", "~/x", "{node}/x", "/scan/", "/2d", "\udce9", "a" * 300]),
    st.one_of(st.sampled_from(["/scan", "lidar_status", "/obstacle_warning"]), HOSTILE),
)
NUMBERS = Values(
    st.sampled_from(["0.3", "0.5", "1", "2.5", "1e-2"]),
    st.sampled_from(["nan", "inf", "-inf", "-1", "0", "1e309", "abc", "", " ", "9" * 400, "0x10"]),
    st.one_of(
        st.sampled_from(["1e-300", "1_0", "\u0661"]),
        st.floats().map(repr),
        st.integers(-(2**70), 2**70).map(str),
    ),
)
WHOLE = Values(
    st.integers(0, 232).map(str),
    st.sampled_from(["", "x", "1.5", "-1", "4294967296", "9" * 50]),
    st.sampled_from(["233", " 7", "0x1"]),
)
THRESHOLD_PARAMS = Values(
    st.sampled_from(["threshold", "", "min_dist", "a.b", "n:t"]),
    st.sampled_from(["bad name!", "1x", "__ns", " ", "a-b", "a..b"]),
    HOSTILE,
)
OUT = Values(
    st.sampled_from(["out", "out2", "a_folder", "new/deeper"]),
    st.sampled_from(["", " ", "existing_file", "existing_file/x", "a_fifo"]),
)
JUNIT = Values(
    st.sampled_from(["j.xml", "existing_file", "out/junit.xml", "a_folder/j.xml"]),
    st.sampled_from(["", "a_folder", "a_folder/", "missing/j.xml", "a_fifo", "new/"]),
)
FAULTS = Values(
    st.sampled_from(["noisy", "drop(rate=0.1)", "lossy_link", "dropouts_nan"]),
    st.sampled_from(["bogus", "drop(rate="]),
    st.sampled_from(["", "noisy,,", "drop(rate=2)"]),
)
REGEXES = Values(
    st.sampled_from(["(?P<distance>[0-9.]+)", "(?P<distance>[0-9.]+).*"]),
    st.sampled_from(["(", "[", "(?P<angle>x"]),
    st.sampled_from(["", "\x00", "x"]),
)
# option -> (its values, percent of command lines that give it)
OPTIONS: dict[str, tuple[Values, int]] = {
    "--scan-topic": (TOPICS, 25),
    "--status-topic": (TOPICS, 20),
    "--warning-topic": (TOPICS, 20),
    "--threshold-param": (THRESHOLD_PARAMS, 20),
    "--threshold": (NUMBERS, 25),
    "--timeout": (NUMBERS, 15),
    "--ready-timeout": (NUMBERS, 10),
    "--seed": (WHOLE, 15),
    "--domain-id": (WHOLE, 10),
    "--out": (OUT, 15),
    "--junit-xml": (JUNIT, 15),
    "--faults": (FAULTS, 10),
    "--status-regex": (REGEXES, 10),
}
PARAMS = st.one_of(
    st.sampled_from(["lidar_topic:=/a", "threshold:=0.1", "a:=[1", "1a:=1", "a b:=1", ":=1"]),
    st.builds(lambda name, value: f"{name}:={value}", HOSTILE, HOSTILE),
)
LINKS = Values(st.just("inprocess"), st.sampled_from(["", " inprocess", "carrier_pigeon"]))
SCENARIOS = Values(
    st.sampled_from(["tiny.yaml"] * 6 + ["approach_wall"]),
    st.sampled_from(["nope", "", "a_folder", "existing_file"]),
)


def percent(draw: st.DrawFn, chance: int) -> bool:
    """True `chance` times in 100 (sampled_from draws evenly; floats would not)."""
    return draw(st.sampled_from(range(100))) < chance


def value(draw: st.DrawFn, values: Values, good: int = 75, bad: int = 15) -> tuple[str, bool]:
    """A value that should work (`good` %), one that cannot (`bad` %) or fuzz; and if it cannot."""
    roll = draw(st.sampled_from(range(100)))
    if roll < good:
        return draw(values.good), False
    if roll < good + bad or values.fuzz.is_empty:
        return draw(values.bad), True
    return draw(values.fuzz), False


@st.composite
def command_lines(draw: st.DrawFn) -> tuple[list[str], bool]:
    """`run SCENARIO --link L` and options in random order; and if it must be refused."""
    scenario, bad_scenario = value(draw, SCENARIOS, good=90, bad=10)
    link, bad_link = value(draw, LINKS, good=90, bad=10)
    refused = bad_scenario or bad_link
    args: list[list[str]] = []
    for option, (values, chance) in OPTIONS.items():
        if percent(draw, chance):
            text, cannot = value(draw, values)
            args.append([option, text])
            refused |= cannot
    if percent(draw, 8):  # refused over inprocess, and any other link here is bad: exit 2
        args += [["--param", p] for p in draw(st.lists(PARAMS, min_size=1, max_size=3))]
        refused = True
    order = draw(st.permutations(range(len(args))))
    flat = [item for i in order for item in args[i]]
    return ["run", scenario, "--link", link, *flat], refused


def assert_records_parse(argv: list[str], workdir: Path) -> None:
    """What a run that reached a verdict wrote is readable: JUnit by an XML parser,
    JSON, and MCAP by the independent reader."""
    options = dict(zip(argv[2::2], argv[3::2], strict=True))  # after `run SCENARIO`
    xml: list[Path] = []
    json_files: list[Path] = []
    mcap_files: list[Path] = []
    if "--junit-xml" in options:
        xml.append(workdir / options["--junit-xml"])
    if "--out" in options:
        folder = workdir / options["--out"]
        xml.append(folder / "junit.xml")
        json_files += [folder / "summary.json", *(folder / "scenarios").glob("*.json")]
        mcap_files += (folder / "scenarios").glob("*.mcap")
    for path in xml:
        ET.parse(path)
    for path in json_files:
        json.loads(path.read_text())
    for path in mcap_files:
        with open(path, "rb") as stream:
            reader = make_reader(stream, decoder_factories=[DecoderFactory()])
            assert sum(1 for _ in reader.iter_decoded_messages()) > 0, path


@pytest.fixture()
def workdir(tmp_path: Path) -> Path:
    (tmp_path / "tiny.yaml").write_text(TINY)
    (tmp_path / "existing_file").write_text("not a report\n")
    (tmp_path / "a_folder").mkdir()
    os.mkfifo(tmp_path / "a_fifo")  # not a regular file (never a device: as root, a
    return tmp_path  # broken check would replace /dev/null itself)


def test_generated_command_lines_run_or_are_refused_in_one_line(
    workdir: Path, capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    codes: Counter[int] = Counter()

    @settings(
        max_examples=EXAMPLES,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[
            HealthCheck.function_scoped_fixture,
            HealthCheck.too_slow,
            HealthCheck.data_too_large,
        ],
    )
    @given(command_lines())
    def check(line: tuple[list[str], bool]) -> None:
        argv, refused = line
        outcome = run_in_process(argv, workdir, capfd, monkeypatch)  # no child left running
        codes[outcome.code] += 1
        shown = f"{argv!r}\n{outcome.stdout[-2000:]}\n{outcome.stderr[-2000:]}"
        assert outcome.code in (0, 1, 2), shown
        if refused:  # a value generated as one that cannot work
            assert outcome.code == 2, shown
        assert "Traceback" not in outcome.stderr + outcome.stdout, shown
        if outcome.code == 2:
            lines = outcome.stderr.splitlines()
            assert len(lines) == 1 and outcome.stderr.endswith("\n"), shown
            assert lines[0].startswith("fossbot-hil: error: "), shown
            assert lines[0].isprintable(), shown
        if outcome.code in (0, 1):
            assert_records_parse(argv, workdir)
        hidden = [
            p
            for p in workdir.rglob(".*")
            if TEMPORARY_NAME.fullmatch(p.name) or (p.is_file() and p.name != LOCK_NAME)
        ]
        assert not hidden, (argv, hidden)

    check()
    # The generator must exercise both sides: runs that pass and lines refused.
    assert codes[0] >= EXAMPLES // 10 and codes[2] >= EXAMPLES // 4, codes
