"""Archived hand-ins: unpacked safely into the output folder, every one a row.

Real archives, made here with zipfile and tarfile; the unpacking tests take
milliseconds (the 100 MB member a second or so). The last test grades a
small class of a folder, a zip, a refused tar.gz and a PDF over ROS 2.
"""

from __future__ import annotations

import gzip
import io
import stat
import tarfile
import zipfile
from pathlib import Path

import pytest

from harness.errors import ConfigError
from harness.grading.archives import (
    MAX_FILE_BYTES,
    MAX_STUDENT_MEMBERS,
    Limits,
    Refused,
    unpack,
    unpack_submissions,
)
from harness.grading.discover import Student, discover

NODE = b"import rclpy\n"
MB = 1 << 20


def make_zip(path: Path, members: dict[str, bytes]) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zipped:
        for name, data in members.items():
            zipped.writestr(zipfile.ZipInfo(name), data)  # ZipInfo: the name as given
    return path


def zip_member(zipped: zipfile.ZipFile, name: str, mode: int, data: bytes = b"") -> None:
    """A member with a Unix file type (a link, a fifo), as Info-ZIP stores it."""
    info = zipfile.ZipInfo(name)
    info.create_system = 3
    info.external_attr = mode << 16
    zipped.writestr(info, data)


def tar_member(
    tar: tarfile.TarFile, name: str, data: bytes = b"", *, type_: bytes = tarfile.REGTYPE, **kw
) -> None:
    info = tarfile.TarInfo(name)
    info.type = type_
    info.size = len(data) if type_ == tarfile.REGTYPE else 0
    for key, value in kw.items():
        setattr(info, key, value)
    tar.addfile(info, io.BytesIO(data) if type_ == tarfile.REGTYPE else None)


def make_tar(path: Path, members: dict[str, bytes], mode: str = "w:gz") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with tarfile.open(path, mode) as tar:
        for name, data in members.items():
            tar_member(tar, name, data)
    return path


def graded(*dirs: Path, out: Path) -> dict[str, Student]:
    """The students of `dirs`, their archives unpacked into `out`/unpacked, by name."""
    found = discover(list(dirs), exclude=out)
    return {s.name: s for s in unpack_submissions(found, out / "unpacked")}


def files_below(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize("suffix", [".zip", ".tar.gz"])
def test_a_member_climbing_out_refuses_the_archive(tmp_path: Path, suffix: str) -> None:
    """'x/../../etc/passwd' is the row's reason; nothing of the archive is written."""
    members = {"lab/node.py": NODE, "x/../../passwd": b"pwned"}
    make = make_zip if suffix == ".zip" else make_tar
    make(tmp_path / "class" / f"eve{suffix}", members)
    make_zip(tmp_path / "class" / "ok.zip", {"node.py": NODE})
    out = tmp_path / "class" / "grades"
    eve = graded(tmp_path / "class", out=out)["eve"]
    assert (eve.kind, eve.problem) == (
        "none",
        "archive refused: 'x/../../passwd' would be written outside the submission",
    )
    assert eve.folder == tmp_path / "class" / f"eve{suffix}"
    assert not list(tmp_path.rglob("passwd"))
    assert files_below(out / "unpacked") == ["ok", "ok/node.py"]  # nothing of eve's left


@pytest.mark.parametrize("suffix", [".zip", ".tar"])
def test_an_absolute_name_refuses_the_archive(tmp_path: Path, suffix: str) -> None:
    """A member named /.../escaped.py is refused, not written there (nor below the root)."""
    target = tmp_path / "escaped.py"
    make = make_zip if suffix == ".zip" else make_tar
    make(tmp_path / "class" / f"eve{suffix}", {"node.py": NODE, str(target): NODE})
    (eve,) = graded(tmp_path / "class", out=tmp_path / "out").values()
    assert eve.problem == f"archive refused: {str(target)!r} is an absolute path"
    assert not target.exists() and not list((tmp_path / "out").rglob("escaped.py"))


@pytest.mark.parametrize("suffix", [".zip", ".tgz"])
def test_links_are_never_made(tmp_path: Path, suffix: str) -> None:
    """A link to a file outside, and a link to a folder outside with a file written
    'through' it: no link is made, nothing lands outside, the node is still found."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.txt").write_text("the instructor's")
    archive = tmp_path / "class" / f"mallory{suffix}"
    archive.parent.mkdir()
    if suffix == ".zip":
        with zipfile.ZipFile(archive, "w") as zipped:
            zipped.writestr("lab/node.py", NODE)
            zip_member(
                zipped, "lab/secret.txt", stat.S_IFLNK | 0o777, str(outside / "secret.txt").encode()
            )
            zip_member(zipped, "lab/out", stat.S_IFLNK | 0o777, str(outside).encode())
            zipped.writestr("lab/out/pwned.py", b"pwned")
    else:
        with tarfile.open(archive, "w:gz") as tar:
            tar_member(tar, "lab/node.py", NODE)
            tar_member(
                tar, "lab/secret.txt", type_=tarfile.SYMTYPE, linkname=str(outside / "secret.txt")
            )
            tar_member(tar, "lab/out", type_=tarfile.SYMTYPE, linkname=str(outside))
            tar_member(tar, "lab/out/pwned.py", b"pwned")
    out = tmp_path / "out"
    mallory = graded(tmp_path / "class", out=out)["mallory"]
    assert (mallory.kind, mallory.script) == (
        "script",
        out / "unpacked" / "mallory" / "lab" / "node.py",
    )
    unpacked = out / "unpacked" / "mallory"
    assert not any(p.is_symlink() for p in unpacked.rglob("*"))
    assert not (unpacked / "lab" / "secret.txt").exists()
    assert sorted(p.name for p in outside.iterdir()) == ["secret.txt"]
    assert (unpacked / "lab" / "out" / "pwned.py").is_file()  # a plain folder of its own


def test_hard_links_are_never_made(tmp_path: Path) -> None:
    """A hard link to /etc/passwd or to a file of the archive itself: left out."""
    archive = tmp_path / "class" / "hal.tar"
    archive.parent.mkdir()
    with tarfile.open(archive, "w") as tar:
        tar_member(tar, "node.py", NODE)
        tar_member(tar, "passwd", type_=tarfile.LNKTYPE, linkname="/etc/passwd")
        tar_member(tar, "copy.py", type_=tarfile.LNKTYPE, linkname="node.py")
    out = tmp_path / "out"
    hal = graded(tmp_path / "class", out=out)["hal"]
    assert hal.kind == "script"
    assert files_below(out / "unpacked" / "hal") == ["node.py"]


def test_a_node_that_was_a_link_is_named_in_the_reason(tmp_path: Path) -> None:
    """Left-out links explain a student with no node (a package symlinked into src/)."""
    archive = tmp_path / "class" / "lin.tgz"
    archive.parent.mkdir()
    with tarfile.open(archive, "w:gz") as tar:
        tar_member(tar, "ws/src/pkg", type_=tarfile.SYMTYPE, linkname="/home/lin/pkg")
    lin = graded(tmp_path / "class", out=tmp_path / "out")["lin"]
    assert lin.problem == (
        "no node found: no package.xml and no .py file; "
        "links in the archive are not unpacked: 'ws/src/pkg'"
    )


@pytest.mark.parametrize(
    ("type_", "what"),
    [
        (tarfile.CHRTYPE, "a character device"),
        (tarfile.BLKTYPE, "a block device"),
        (tarfile.FIFOTYPE, "a fifo"),
    ],
)
def test_device_files_and_fifos_refuse_the_archive(tmp_path: Path, type_: bytes, what: str) -> None:
    archive = tmp_path / "class" / "dev.tar.gz"
    archive.parent.mkdir()
    with tarfile.open(archive, "w:gz") as tar:
        tar_member(tar, "node.py", NODE)
        tar_member(tar, "lab/sda", type_=type_, devmajor=8, devminor=0)
    out = tmp_path / "out"
    dev = graded(tmp_path / "class", out=out)["dev"]
    assert dev.problem == f"archive refused: 'lab/sda' is {what}"
    assert files_below(out / "unpacked") == []


def test_a_fifo_in_a_zip_refuses_it(tmp_path: Path) -> None:
    archive = tmp_path / "class" / "dev.zip"
    archive.parent.mkdir()
    with zipfile.ZipFile(archive, "w") as zipped:
        zip_member(zipped, "pipe", stat.S_IFIFO | 0o644)
    dev = graded(tmp_path / "class", out=tmp_path / "out")["dev"]
    assert dev.problem == "archive refused: 'pipe' is a fifo"


def test_a_zip_bomb_member_is_stopped_at_the_file_limit(tmp_path: Path) -> None:
    """100 MB and a byte of zeros, 100 kB packed: refused, and nothing of it kept."""
    archive = tmp_path / "class" / "bomb.zip"
    archive.parent.mkdir()
    zeros = bytes(MB)
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zipped:
        zipped.writestr("node.py", NODE)
        with zipped.open("lab/zeros.bin", "w", force_zip64=True) as member:
            for _ in range(MAX_FILE_BYTES // MB):
                member.write(zeros)
            member.write(b"\0")
    assert archive.stat().st_size < MB
    out = tmp_path / "out"
    bomb = graded(tmp_path / "class", out=out)["bomb"]
    assert bomb.problem == (
        "archive refused: 'lab/zeros.bin' unpacks to more than 100 MB (the limit for one file)"
    )
    assert files_below(out / "unpacked") == []


def test_a_zip_whose_headers_lie_about_a_size_is_not_unpacked(tmp_path: Path) -> None:
    """Headers that say 10 bytes for a member of 1 MB: the read stops and the check fails."""
    archive = tmp_path / "liar.zip"
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zipped:
        zipped.writestr("zeros.bin", bytes(MB))
    data = bytearray(archive.read_bytes())
    true_size = MB.to_bytes(4, "little")
    assert data.count(true_size) == 2  # the local header's and the central directory's
    archive.write_bytes(bytes(data).replace(true_size, (10).to_bytes(4, "little")))
    with pytest.raises(Refused, match="archive could not be unpacked: Bad CRC-32"):
        unpack(archive, tmp_path / "dest")
    assert not (tmp_path / "dest").exists() or files_below(tmp_path / "dest") == []


def test_the_total_is_counted_while_reading(tmp_path: Path) -> None:
    """Three files of 400 kB under a 1 MB limit: the third refuses the archive."""
    archive = make_tar(tmp_path / "big.tar.gz", {f"f{i}.bin": bytes(400_000) for i in range(3)})
    limits = Limits(total_bytes=MB, members=100)
    with pytest.raises(Refused, match=r"^archive refused: it unpacks to more than 1 MB \(the "):
        unpack(archive, tmp_path / "dest", limits)
    assert files_below(tmp_path / "dest") == []


def test_a_tar_header_that_makes_tarfile_read_without_end_is_stopped(tmp_path: Path) -> None:
    """A pax header of 20 MB (tarfile reads one whole): the stream itself is capped."""
    info = tarfile.TarInfo("././@PaxHeader")
    info.type = tarfile.XHDTYPE
    info.size = 20 * MB
    raw = info.tobuf(tarfile.USTAR_FORMAT) + b"9" * info.size + bytes(1024)
    archive = tmp_path / "pax.tar.gz"
    archive.write_bytes(gzip.compress(raw))
    with pytest.raises(Refused, match="it unpacks to more than 1 MB"):
        unpack(archive, tmp_path / "dest", Limits(total_bytes=MB, members=10))


def test_too_many_members_refuse_the_archive(tmp_path: Path) -> None:
    """20,001 empty files in a zip (its directory says so); 11 in a tar with a limit of 10."""
    archive = tmp_path / "class" / "many.zip"
    archive.parent.mkdir()
    with zipfile.ZipFile(archive, "w") as zipped:
        for i in range(MAX_STUDENT_MEMBERS + 1):
            zipped.writestr(f"f/{i}.txt", b"")
    many = graded(tmp_path / "class", out=tmp_path / "out")["many"]
    assert many.problem == (
        "archive refused: more than 20,000 files and folders (the limit for one student's archive)"
    )
    tar = make_tar(tmp_path / "many.tar", {f"f/{i}.txt": b"" for i in range(11)}, mode="w")
    with pytest.raises(Refused, match="more than 10 files and folders"):
        unpack(tar, tmp_path / "dest", Limits(total_bytes=MB, members=10))
    assert files_below(tmp_path / "dest") == []


def test_a_broken_archive_is_a_row(tmp_path: Path) -> None:
    """Not a zip at all, or a tar.gz cut short: the row says it could not be unpacked."""
    whole = make_tar(tmp_path / "whole.tar.gz", {"node.py": NODE * 10_000})
    (tmp_path / "class").mkdir()
    (tmp_path / "class" / "cut.tar.gz").write_bytes(whole.read_bytes()[:200])
    (tmp_path / "class" / "junk.zip").write_bytes(b"not a zip at all")
    students = graded(tmp_path / "class", out=tmp_path / "out")
    assert students["junk"].problem == "archive could not be unpacked: File is not a zip file"
    cut = students["cut"]
    assert cut.kind == "none" and cut.problem is not None
    assert cut.problem.startswith("archive could not be unpacked: "), cut.problem
    assert files_below(tmp_path / "out" / "unpacked") == []


def test_encrypted_and_bzip2_zip_members_are_refused(tmp_path: Path) -> None:
    enc = tmp_path / "class" / "enc.zip"
    make_zip(enc, {"node.py": NODE})
    data = bytearray(enc.read_bytes())  # set the 'encrypted' flag bit in both headers
    data[6] |= 1
    central = data.index(b"PK\x01\x02")
    data[central + 8] |= 1
    enc.write_bytes(bytes(data))
    with zipfile.ZipFile(tmp_path / "class" / "bz.zip", "w", zipfile.ZIP_BZIP2) as zipped:
        zipped.writestr("node.py", NODE)
    students = graded(tmp_path / "class", out=tmp_path / "out")
    assert students["enc"].problem == "archive refused: 'node.py' is encrypted"
    assert students["bz"].problem == (
        "archive refused: 'node.py' is compressed with method 12 "
        "(only stored and deflate members are unpacked)"
    )


def test_a_wrapper_folder_is_looked_through(tmp_path: Path) -> None:
    """lab07/ inside the zip (and macOS's litter beside it) is the hand-in; src/ is not."""
    make_zip(
        tmp_path / "class" / "erin.zip",
        {
            "lab07/lidar_node.py": NODE,
            "lab07/notes.txt": b"",
            "__MACOSX/lab07/._lidar_node.py": b"\0",
            ".DS_Store": b"\0",
        },
    )
    make_zip(tmp_path / "class" / "finn.zip", {"src/pkg/package.xml": b"<package/>"})
    out = tmp_path / "out"
    students = graded(tmp_path / "class", out=out)
    assert students["erin"].script == out / "unpacked" / "erin" / "lab07" / "lidar_node.py"
    assert not (out / "unpacked" / "erin" / "__MACOSX").exists()
    finn = students["finn"]
    assert (finn.kind, finn.folder) == ("workspace", out / "unpacked" / "finn")
    assert finn.base_paths == (out / "unpacked" / "finn" / "src" / "pkg",)


def test_a_tar_gz_package_and_a_zipped_script_are_students(tmp_path: Path) -> None:
    """Named after their archives, unpacked below OUT/unpacked, beside a folder student."""
    make_tar(
        tmp_path / "class" / "alex.tar.gz",
        {
            "fossbot_lidar_processing/package.xml": b"<package/>",
            "fossbot_lidar_processing/setup.py": b"",
            "fossbot_lidar_processing/fossbot_lidar_processing/node.py": NODE,
        },
    )
    make_zip(tmp_path / "class" / "Ben Brown.ZIP", {"lidar_node.py": NODE, "helpers.py": b""})
    (tmp_path / "class" / "cleo").mkdir()
    (tmp_path / "class" / "cleo" / "node.py").write_bytes(NODE)
    (tmp_path / "class" / "dan_report.pdf").write_bytes(b"%PDF-1.4")
    out = tmp_path / "out"
    students = graded(tmp_path / "class", out=out)
    assert [(s.name, s.slug, s.kind) for s in students.values()] == [
        ("alex", "alex", "package"),
        ("Ben Brown", "Ben_Brown", "script"),
        ("cleo", "cleo", "script"),
        ("dan_report.pdf", "dan_report.pdf", "none"),
    ]
    assert students["alex"].base_paths == (out / "unpacked" / "alex" / "fossbot_lidar_processing",)
    assert students["Ben Brown"].script == out / "unpacked" / "Ben_Brown" / "lidar_node.py"
    assert students["dan_report.pdf"].problem == "not a submission: a file, not a folder or archive"


@pytest.mark.parametrize(("suffix", "mode"), [(".tar.bz2", "w:bz2"), (".txz", "w:xz")])
def test_bzip2_and_xz_tars_are_read(tmp_path: Path, suffix: str, mode: str) -> None:
    make_tar(tmp_path / "class" / f"gus{suffix}", {"gus/node.py": NODE}, mode=mode)
    gus = graded(tmp_path / "class", out=tmp_path / "out")["gus"]
    assert gus.script == tmp_path / "out" / "unpacked" / "gus" / "gus" / "node.py"


def test_names_are_unique_with_the_folder_students(tmp_path: Path) -> None:
    """alex/ in mon and alex.zip in tue: mon/alex and tue/alex; alex/ beside alex.zip in
    one folder: the archive keeps its suffix."""
    (tmp_path / "mon" / "alex").mkdir(parents=True)
    (tmp_path / "mon" / "alex" / "node.py").write_bytes(NODE)
    make_zip(tmp_path / "tue" / "alex.zip", {"node.py": NODE})
    students = graded(tmp_path / "mon", tmp_path / "tue", out=tmp_path / "out")
    assert [(s.name, s.slug) for s in students.values()] == [
        ("mon/alex", "mon_alex"),
        ("tue/alex", "tue_alex"),
    ]
    make_zip(tmp_path / "mon" / "alex.zip", {"node.py": NODE})
    students = graded(tmp_path / "mon", out=tmp_path / "out2")
    assert [(s.name, s.slug) for s in students.values()] == [
        ("mon/alex", "mon_alex"),
        ("mon/alex.zip", "mon_alex.zip"),
    ]


def test_a_class_archive_is_read_as_its_folder(tmp_path: Path) -> None:
    """An archive given as DIR: a folder of students (one a zip, one a PDF) or, when it is
    one hand-in, one student named after it."""
    inner = make_zip(tmp_path / "ben.zip", {"ben/node.py": NODE})
    with tarfile.open(tmp_path / "mon.tgz", "w:gz") as tar:
        tar_member(tar, "submissions/alex/node.py", NODE)
        tar.add(inner, "submissions/ben.zip")
        tar_member(tar, "submissions/cleo.pdf", b"%PDF")
    make_zip(tmp_path / "maria.zip", {"package.xml": b"<package/>"})
    out = tmp_path / "out"
    students = graded(tmp_path / "mon.tgz", tmp_path / "maria.zip", out=out)
    assert {n: s.kind for n, s in students.items()} == {
        "alex": "script",
        "ben": "script",
        "cleo.pdf": "none",
        "maria": "package",
    }
    assert students["ben"].script == out / "unpacked" / "ben" / "ben" / "node.py"
    assert students["maria"].folder == out / "unpacked" / "maria"


def test_archives_count_as_possible_students(tmp_path: Path) -> None:
    """A folder of zips is not 'no students found' (their content is not known yet); a
    folder holding only a PDF is; a missing archive is named as one."""
    make_zip(tmp_path / "zips" / "ana.zip", {"node.py": NODE})
    assert [a.name for a in discover([tmp_path / "zips"]).archives] == ["ana"]
    (tmp_path / "pdfs").mkdir()
    (tmp_path / "pdfs" / "ana.pdf").write_bytes(b"%PDF")
    with pytest.raises(ConfigError, match="no students found"):
        discover([tmp_path / "pdfs"])
    with pytest.raises(ConfigError, match="class.zip: no such archive"):
        discover([tmp_path / "class.zip"])
    assert not (tmp_path / "out").exists()  # discovery writes nothing


def test_prepare_out_removes_last_times_unpacked_archives(tmp_path: Path) -> None:
    from harness.commands.grade import prepare_out
    from harness.grading.discover import GRADES_MARKER

    out = tmp_path / "grades"
    (out / "unpacked" / "old").mkdir(parents=True)
    (out / GRADES_MARKER).write_text("")
    prepare_out(out).release()
    assert not (out / "unpacked").exists()


# A class of a folder, a zip, a refused tar.gz and a PDF, graded end to end:
# tests/grading/test_grading_course.py.
