"""A grading worker's warm judge serves its script students one after another in one
sandbox: the next student's node sees neither the previous student's files nor anything
they left (a process in a session of its own, a file in the shared /dev/shm).

Real parts: bubblewrap, the embedded Dask cluster (one worker, so both students go to
the same judge), the students' scripts started as nodes.
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import uuid
from pathlib import Path

import pytest
from command_line import COMMAND
from short_scenarios import NEAR_WALL

from harness.sandbox.bwrap import bwrap_argv
from harness.sandbox.views import run_view

pytestmark = [pytest.mark.ros, pytest.mark.timeout(180)]

MARK = f"SPY-{uuid.uuid4().hex[:8]}"  # in the first student's files and what it leaves

# The first student: leaves a process in a session of its own and a file in /dev/shm,
# then stops (its row does not matter).
SPY = f"""# {MARK}
import subprocess, sys
subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)", "{MARK}"],
                 start_new_session=True, stdin=subprocess.DEVNULL,
                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
with open("/dev/shm/{MARK}", "w") as out:
    out.write("{MARK}")
sys.exit("left")
"""

# The next student: looks for all of that (the mark spelled backwards in its own file) and
# says what it found as its failure.
PROBE = f"""
import json, os, sys
mark = "{MARK[::-1]}"[::-1]
own = os.path.dirname(os.path.abspath(__file__))
found = {{"procs": [], "shm": [], "files": [], "beside": []}}
for pid in os.listdir("/proc"):
    try:
        with open(f"/proc/{{pid}}/cmdline", "rb") as f:
            if mark.encode() in f.read():
                found["procs"].append(pid)
    except OSError:
        pass
found["shm"] = [n for n in os.listdir("/dev/shm") if mark in n]
found["beside"] = [n for n in os.listdir(os.path.dirname(own)) if n != os.path.basename(own)]
skip = {{"/proc", "/sys", "/dev", "/usr", "/etc", "/opt", sys.prefix, sys.base_prefix, own}}
for root, dirs, files in os.walk("/"):
    dirs[:] = [d for d in dirs if os.path.join(root, d) not in skip]
    for name in files:
        try:
            with open(os.path.join(root, name), "rb") as f:
                if mark.encode() in f.read(100000):
                    found["files"].append(os.path.join(root, name))
        except OSError:
            pass
sys.exit("PROBE " + json.dumps(found))
"""


def leftovers() -> list[str]:
    """Processes anywhere on the machine with the first student's mark."""
    found = []
    for proc in Path("/proc").iterdir():
        try:
            if proc.name.isdigit() and MARK.encode() in (proc / "cmdline").read_bytes():
                found.append(proc.name)
        except OSError:
            continue
    return found


def test_the_next_student_sees_nothing_of_the_previous_one(tmp_path: Path) -> None:
    for name, source in (("a_spy", SPY), ("b_probe", PROBE)):
        (tmp_path / "class" / name).mkdir(parents=True)
        (tmp_path / "class" / name / "fossbot_lidar_node.py").write_text(source)
    (tmp_path / "near_wall.yaml").write_text(NEAR_WALL)
    done = subprocess.run(
        [*COMMAND, "grade", "class", "--scenario", "near_wall.yaml", "--no-audit"]
        + ["--workers", "1", "--out", "grades"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=150,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    with open(tmp_path / "grades" / "grades.csv", encoding="utf-8", newline="") as table:
        rows = {row["student"]: row for row in csv.DictReader(table)}
    failure = rows["b_probe"]["first_failure"]
    assert "PROBE " in failure, failure
    said = json.loads(failure.split("PROBE ", 1)[1].split("}", 1)[0] + "}")
    assert said == {"procs": [], "shm": [], "files": [], "beside": []}, said
    job = json.loads((tmp_path / "grades" / "grader" / "b_probe" / "job.json").read_text())
    assert "/.slots/" in job["options"]["node"]  # judged by the worker's warm judge
    assert not (tmp_path / "grades" / "grader" / ".slots").exists()
    assert not (tmp_path / "grades" / "grader" / "frames.pickle").exists()  # the judges' only
    assert not leftovers(), "a process of the first student outlived the grading"


def test_between_students_the_judge_ends_every_process_but_its_own() -> None:
    """In a sandbox's PID namespace: a process in a session of its own and its child."""
    script = (
        "import subprocess, sys\n"
        "from harness.grading.warm_judge import end_strays, _pids, _alive\n"
        'code = \'import subprocess, sys, time; subprocess.Popen([sys.executable, "-c", '
        '"import time; time.sleep(600)"]); time.sleep(600)\'\n'
        "subprocess.Popen([sys.executable, '-c', code], start_new_session=True)\n"
        "subprocess.Popen([sys.executable, '-c', 'import signal; "
        "signal.signal(signal.SIGTERM, signal.SIG_IGN); import time; time.sleep(600)'])\n"
        "assert end_strays(), 'still running'\n"
        "print(len([p for p in _pids() if p != 1 and _alive(p)]))\n"
    )
    argv = bwrap_argv(run_view([], [], []), [sys.executable, "-c", script])
    done = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "1", done.stdout  # itself alone
