"""The sandbox's parts: the bwrap command line, the limits, what a refusal reads like,
and grade's one-line refusal (exit 2, nothing written) where bubblewrap cannot run."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from command_line import COMMAND

from harness.sandbox.bwrap import HOME, View, bwrap_argv
from harness.sandbox.limits import SandboxLimits
from harness.sandbox.refusals import refusal_of
from harness.sandbox.views import node_view, run_view, sandbox_env


def pairs(argv: list[str], option: str) -> list[str]:
    return [argv[i + 1] for i, a in enumerate(argv) if a == option]


def test_a_view_shows_only_its_folders_each_at_its_own_path() -> None:
    view = View(read_only=("/usr", "/a/b"), writable=("/a/b/out",), links={"/bin": "usr/bin"})
    argv = bwrap_argv(view, ["true"])
    assert argv[-2:] == ["--", "true"]
    assert {"--unshare-user", "--unshare-net", "--unshare-pid", "--die-with-parent"} <= set(argv)
    assert pairs(argv, "--ro-bind") == ["/usr", "/a/b"] and pairs(argv, "--bind") == ["/a/b/out"]
    # the writable folder inside a read-only one is mounted after it (else it is hidden)
    assert argv.index("/a/b/out") > argv.index("/a/b")
    assert pairs(argv, "--symlink") == ["usr/bin"] and "--clearenv" in argv
    assert pairs(argv, "--uid") == ["1000"]  # never uid 0 inside, even for root
    assert argv.index("--tmpfs") < argv.index("--ro-bind")  # /tmp first, then what is in it


def test_a_nested_view_shares_network_pids_and_shared_memory() -> None:
    argv = bwrap_argv(node_view([]), ["node"])
    assert "--unshare-net" not in argv and "--unshare-pid" not in argv
    assert ["/dev/shm", "/dev/shm"] == argv[argv.index("/dev/shm") : argv.index("/dev/shm") + 2]
    assert "--clearenv" not in argv and "FOSSBOT_HIL_NODE_SANDBOX" in pairs(argv, "--unsetenv")
    assert pairs(argv, "--setenv")[::1].count("HOME") == 1 and HOME in argv


def test_the_environment_keeps_what_python_and_ros_read_only(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("GITHUB_TOKEN", "secret")
    monkeypatch.setenv("ROS_DOMAIN_ID", "7")
    env = sandbox_env()
    assert "GITHUB_TOKEN" not in env and env["ROS_DOMAIN_ID"] == "7" and "PATH" in env


def test_the_run_view_shows_the_harness_and_this_python_read_only(tmp_path: Path) -> None:
    import harness

    view = run_view([], [tmp_path / "hidden.yaml"], [tmp_path])
    assert str(Path(harness.__file__).resolve().parent) in view.read_only
    assert sys.prefix in view.read_only and str(tmp_path.resolve()) in view.writable
    assert str(tmp_path / "hidden.yaml") not in view.read_only  # only files that exist


def test_limits_are_set_inside_by_prlimit() -> None:
    assert SandboxLimits(512, 32).prefix() == ["prlimit", f"--as={512 << 20}", "--nproc=32", "--"]


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("OSError: [Errno 30] Read-only file system: 'x'", "a write outside"),
        ("ConnectionRefusedError: [Errno 111] Connection refused", "no network"),
        ("OSError: [Errno 101] Network is unreachable", "no network"),
        ("MemoryError", "memory limit (1024 MB per process)"),
        ("BlockingIOError: [Errno 11] Resource temporarily unavailable (fork)", "process limit"),
    ],
)
def test_a_refusal_is_told_as_the_sandbox_s(text: str, words: str) -> None:
    found = refusal_of(text, SandboxLimits(1024, 64))
    assert found is not None and words in found


def test_an_ordinary_failure_is_not_blamed_on_the_sandbox() -> None:
    assert refusal_of("ValueError: no scan yet", SandboxLimits(1024, 64)) is None


def grade_with_path(tmp_path: Path, path: str, *extra: str) -> subprocess.CompletedProcess[str]:
    (tmp_path / "class" / "ana").mkdir(parents=True)
    (tmp_path / "class" / "ana" / "lidar_node.py").write_text("print('hi')\n")
    return subprocess.run(
        [*COMMAND, "grade", "class", "--scenario", "approach_wall", "--no-audit", *extra],
        cwd=tmp_path,
        env={**os.environ, "PATH": path},
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_grade_without_bubblewrap_exits_2_with_the_fix(tmp_path: Path) -> None:
    done = grade_with_path(tmp_path, str(tmp_path / "nothing-here"))
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "bwrap is not installed" in lines[0], done.stderr
    assert "apt install bubblewrap" in lines[0] and "--no-sandbox" in lines[0]
    assert not (tmp_path / "grades").exists()  # before any student, nothing written


def test_grade_where_bubblewrap_is_refused_names_user_namespaces(tmp_path: Path) -> None:
    """A machine whose kernel refuses the sandbox cannot be made here: a stand-in bwrap
    answers as bwrap does there."""
    fake = tmp_path / "bin"
    fake.mkdir()
    (fake / "bwrap").write_text(
        "#!/bin/sh\necho 'bwrap: setting up uid map: Permission denied' >&2\nexit 1\n"
    )
    (fake / "bwrap").chmod(0o755)
    done = grade_with_path(tmp_path, f"{fake}:/usr/bin:/bin")
    assert done.returncode == 2, done.stdout + done.stderr
    assert "bwrap cannot make a sandbox" in done.stderr and "uid map" in done.stderr
    assert "AppArmor" in done.stderr and "--no-sandbox" in done.stderr


def test_no_sandbox_says_so(tmp_path: Path) -> None:
    done = grade_with_path(tmp_path, os.environ["PATH"], "--no-sandbox", "--timeout", "2")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "warning: --no-sandbox: each student's build and node run with your rights" in (
        done.stdout
    )
