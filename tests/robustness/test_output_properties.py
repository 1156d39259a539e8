"""Whatever bytes a node under test writes, a run gives a verdict and records that read back.

Hypothesis generates what a processing function prints (stdout and stderr)
and the status it publishes, from arbitrary bytes; the whole `fossbot-hil
run` path handles it: the function in its forked child, the oracle, the
terminal table, the report folder and JUnit. Asserted for each example:
exit code 0 or 1, no traceback, a clean terminal, JUnit read by an XML
parser, JSON, the MCAP recording read by the independent reader (with the
status as published, bounded), no child left running, no temporary file
left behind.
"""

from __future__ import annotations

import json
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hostile_checks import run_in_process
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from property_depth import examples

from harness.atomic_write import TEMPORARY_NAME
from harness.safe_text import TEXT_LIMIT

pytestmark = [pytest.mark.timeout(600), pytest.mark.slow]

EXAMPLES = examples(20)  # each writes a whole report folder (a plot, a recording); 200+ at the
# writers alone: tests/report/test_report_text_safety.py
ONE_TICK = """\
description: One tick beside a wall.
obstacles:
  - {type: wall, start: [1.0, -1.0], end: [1.0, 1.0]}
motion:
  segments:
    - until: {duration: 0.05}
"""
PROCESSOR = """\
import os, sys

def process(scan, threshold):
    data = open(os.environ["FOSSBOT_TEST_OUTPUT"], "rb").read()
    printed, status = data.split(b"\\0SPLIT\\0", 1)
    sys.stdout.buffer.write(printed)
    sys.stderr.buffer.write(printed[::-1])
    return status.decode("utf-8", "surrogateescape"), None
"""
CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")

BYTES = st.one_of(
    st.binary(max_size=300),
    st.text(max_size=200).map(lambda t: t.encode("utf-8", "surrogatepass")),
    st.sampled_from([b"\x1b[2J\x1b[31m", b"\x00\x07\r\x0b", b"\xe2\x80\xae", b"\xff\xfe"]),
    st.integers(TEXT_LIMIT - 2, TEXT_LIMIT * 3).map(lambda n: b"x" * n),
)


def _read_mcap(path: Path) -> list[str]:
    """The statuses in a recording, read with mcap-ros2-support's own decoder."""
    statuses = []
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, channel, _, message in reader.iter_decoded_messages():
            if channel.topic == "/lidar_status":
                statuses.append(message.data)
    return statuses


def test_any_output_bytes_give_a_verdict_and_readable_records(
    tmp_path: Path,
    capfd: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    (tmp_path / "one_tick.yaml").write_text(ONE_TICK)
    (tmp_path / "processor.py").write_text(PROCESSOR)
    output = tmp_path / "output.bin"
    monkeypatch.setenv("FOSSBOT_TEST_OUTPUT", str(output))

    @settings(
        max_examples=EXAMPLES,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    )
    @given(printed=BYTES, status=BYTES)
    def check(printed: bytes, status: bytes) -> None:
        output.write_bytes(printed + b"\0SPLIT\0" + status)
        out = tmp_path / "report"
        argv = [
            "run",
            "one_tick.yaml",
            "--link",
            "inprocess",
            "--processor",
            "processor.py:process",
            "--out",
            "report",
            "--junit-xml",
            "junit.xml",
        ]
        outcome = run_in_process(argv, tmp_path, capfd, monkeypatch)  # no child left
        shown = f"{printed[:80]!r} {status[:80]!r}\n{outcome.stdout[-1500:]}{outcome.stderr}"
        assert outcome.code in (0, 1), shown
        assert "Traceback" not in outcome.stdout + outcome.stderr, shown
        assert not CONTROL.search(outcome.stdout + outcome.stderr), shown
        ET.parse(tmp_path / "junit.xml")
        ET.parse(out / "junit.xml")
        summary = json.loads((out / "summary.json").read_text())
        details = json.loads((out / "scenarios" / "one_tick.json").read_text())
        assert summary["scenarios"][0]["ticks"] == len(details["records"]) > 0, shown
        statuses = _read_mcap(out / "scenarios" / "one_tick.mcap")
        assert statuses and all(len(s) <= TEXT_LIMIT for s in statuses), shown
        left = [p for p in tmp_path.rglob(".*") if TEMPORARY_NAME.fullmatch(p.name)]
        assert not left, left

    check()
    assert not os.listdir(tmp_path / "tmp") or all(
        name.startswith("fossbot-hil-") for name in os.listdir(tmp_path / "tmp")
    )
