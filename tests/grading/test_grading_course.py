"""A course's grading, end to end: folders, a zip, a refused archive and a loose file, a
roster, a grading file with
weights and a hidden scenario named by a relative path; the tables, the gradebook, a
Gradescope results.json per student, and students' files free of the instructor's paths.

Real parts: students' nodes in their own processes over Fast DDS, the embedded Dask
cluster, a real zip file.
"""

from __future__ import annotations

import contextlib
import csv
import io
import shutil
import sys
import tarfile
import zipfile
from pathlib import Path

import pytest
from gradescope_schema import check_gradescope, read_results
from grading_class import STUDENT_NODE

from harness.cli import main
from harness.grading.discover import GRADES_MARKER

REPO = Path(__file__).resolve().parents[2]
HIDDEN = "narrow_corridor"

pytestmark = pytest.mark.timeout(240)


def node_script(folder: Path, variant: str) -> Path:
    """A one-file hand-in running the test suite's student node as `variant`."""
    folder.mkdir(parents=True)  # the whole node in the student's folder, as a hand-in is
    (folder / "lidar_node.py").write_text(
        f"import sys\n\nsys.argv[1:1] = [{variant!r}]\n" + STUDENT_NODE.read_text()
    )
    return folder


def zipped(folder: Path) -> Path:
    """`folder` handed in as `folder`.zip (wrapped in its own folder, as LMSs export)."""
    archive = folder.with_suffix(".zip")
    with zipfile.ZipFile(archive, "w") as handle:
        for path in sorted(folder.rglob("*")):
            handle.write(path, str(path.relative_to(folder.parent)))
    shutil.rmtree(folder)
    return archive


@pytest.fixture(scope="module")
def course(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The instructor's folder: class/, course/grading.yaml, course/hidden/, roster.csv."""
    root = tmp_path_factory.mktemp("instructor")
    node_script(root / "class" / "alex", "correct")
    zipped(node_script(root / "class" / "bea", "angle_in_degrees"))
    node_script(root / "class" / "carl", "crash_when_nothing_in_range")
    with tarfile.open(root / "class" / "mallory.tar.gz", "w:gz") as handle:  # climbs out
        member = tarfile.TarInfo("x/../../etc/passwd")
        member.size = 5
        handle.addfile(member, io.BytesIO(b"pwned"))
    (root / "class" / "notes.pdf").write_bytes(b"%PDF-1.4")
    (root / "course" / "hidden").mkdir(parents=True)
    shutil.copy(REPO / "examples" / f"{HIDDEN}.yaml", root / "course" / "hidden")
    (root / "course" / "grading.yaml").write_text(
        "scenarios:\n"
        "  - approach_wall\n"
        "  - scenario: out_of_range\n    weight: 2\n"
        f"  - scenario: hidden/{HIDDEN}.yaml\n    weight: 3\n    hidden: true\n"
        "points: 60\n"
        "gradebook: {column: 'Lab 07: LIDAR node', ids: SIS Login ID}\n"
    )
    (root / "course" / "roster.csv").write_text(
        "folder,id,name\nalex,s100,Alex A\nbea,s200,Bea B\ncarl,s300,Carl C\ndan,s400,Dan D\n"
    )
    return root


@pytest.fixture(scope="module")
def graded(course: Path) -> Path:
    """`fossbot-hil grade` run from the instructor's folder, with relative paths, into the
    folder of an earlier grading (its output kept in grade_output.txt)."""
    earlier = course / "grades"
    earlier.mkdir()
    (earlier / GRADES_MARKER).write_text("written by fossbot-hil grade\n")
    (earlier / "grades.csv").write_text("student,passed\r\nalex,1/1\r\nbea,0/1\r\n")
    said = io.StringIO()
    with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stdout(said):
        patch.chdir(course)
        code = main(
            [
                "grade",
                "class",
                "--grading",
                "course/grading.yaml",
                "--roster",
                "course/roster.csv",
                "--gradescope",
                "--no-audit",
                "--out",
                "grades",
            ]
        )
    (course / "grade_output.txt").write_text(said.getvalue())
    assert code == 0, said.getvalue()
    return course / "grades"


def rows(path: Path) -> dict[str, dict[str, str]]:
    table = csv.DictReader(io.StringIO(path.read_text(encoding="utf-8")))
    return {row.get("student") or row.get("Student", ""): row for row in table}


def test_every_student_on_the_roster_has_a_row_with_id_and_score(graded: Path) -> None:
    table = rows(graded / "grades.csv")
    assert sorted(table) == ["alex", "bea", "carl", "dan", "mallory", "notes.pdf"]
    alex, bea, carl, dan = (table[n] for n in ("alex", "bea", "carl", "dan"))
    assert (alex["id"], alex["score"], alex["passed"]) == ("s100", "60", "3/3")
    assert alex[HIDDEN] == "PASS"  # the class table is the instructor's: names it
    assert bea["approach_wall"] == "FAIL" and float(bea["score"]) < 60
    # carl's node crashed in out_of_range: its missing ticks count as not held
    assert carl["out_of_range"] == "ERROR"
    held, planned = map(int, carl["out_of_range ticks"].split("/"))
    assert held < planned == int(alex["out_of_range ticks"].split("/")[1])
    assert (dan["id"], dan["score"], dan["first_failure"]) == ("s400", "0", "no submission")


def test_every_submission_has_a_row_even_a_refused_archive_or_a_loose_file(
    graded: Path,
) -> None:
    table = rows(graded / "grades.csv")
    assert table["bea"]["node"] == "lidar_node.py (script)"  # unpacked from bea.zip
    assert (graded / "unpacked" / "bea" / "bea" / "lidar_node.py").is_file()
    mallory, pdf = table["mallory"], table["notes.pdf"]
    assert mallory["approach_wall"] == "NOT RUN" and mallory["id"] == ""  # not on the roster
    assert mallory["first_failure"] == (
        "archive refused: 'x/../../etc/passwd' would be written outside the submission"
    )
    assert pdf["first_failure"] == "not a submission: a file, not a folder or archive"
    page = (graded / "grades.html").read_text(encoding="utf-8")
    assert all(name in page for name in table)


def test_the_gradebook_has_the_roster_ids_and_scores_alone(graded: Path) -> None:
    """The grading file's column and id column; a submission not on the roster has no
    row (an id the LMS does not know stops Moodle's import)."""
    table = list(csv.reader(io.StringIO((graded / "gradebook.csv").read_text(encoding="utf-8"))))
    assert table[0] == [
        "Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Lab 07: LIDAR node"
    ]  # fmt: skip
    by_id = {row[3]: row for row in table[1:]}
    assert sorted(by_id) == ["s100", "s200", "s300", "s400"]
    assert by_id["s100"][0] == "Alex A" and by_id["s100"][5] == "60"
    assert by_id["s400"][5] == "0"  # on the roster, nothing handed in
    assert all(row[2] == "" for row in table[1:])  # the ids went under SIS Login ID


def test_grading_into_an_earlier_grading_says_what_it_replaces(course: Path, graded: Path) -> None:
    said = (course / "grade_output.txt").read_text()
    assert "replacing the grading of 2 students from " in said, said


def test_each_student_gets_a_gradescope_results_json_that_hides_the_hidden(graded: Path) -> None:
    for name in ("alex", "bea", "carl"):
        data = read_results(graded / "students" / name / "gradescope" / "results.json")
        check_gradescope(data)
        names = [t["name"] for t in data["tests"]]
        assert names == ["approach_wall", "out_of_range", "hidden 1"]
        assert sum(t["max_score"] for t in data["tests"]) == pytest.approx(60, abs=0.05)
        assert HIDDEN not in str(data)
    alex = read_results(graded / "students" / "alex" / "gradescope" / "results.json")
    assert alex["score"] == pytest.approx(60)


def test_students_files_name_no_instructor_path_nor_the_hidden_scenario(
    graded: Path, course: Path
) -> None:
    secrets = [str(course), str(course.resolve()), sys.executable, str(REPO), HIDDEN]
    checked = 0
    for path in (graded / "students").rglob("*"):
        if path.is_file() and path.suffix in (".html", ".json", ".xml", ".log"):
            text = path.read_text(encoding="utf-8", errors="replace")
            found = [s for s in secrets if s in text]
            assert not found, f"{path.relative_to(graded)} names {found}"
            checked += 1
        assert HIDDEN not in path.name
    assert checked >= 15  # reports, logs, JUnit, results of three students
    report = (graded / "students" / "alex" / "report" / "index.html").read_text()
    assert "hidden 1" in report
