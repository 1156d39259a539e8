"""The bwrap command line that shows a command only part of the machine (pure: no I/O).

A view is a list of host folders, each visible read-only or writable at the
same path; everything else is absent. Every sandbox gets its own user
namespace (no capabilities, even when the grader runs as root), its own
/tmp, home and IPC, and by choice its own network (loopback only) and PID
namespace (everything in it dies with it).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

__all__ = ["HOME", "View", "bwrap_argv"]

HOME = "/home/student"  # the sandbox's home: an empty tmpfs
SCRATCH = "/tmp"  # where a sandboxed command starts: its own tmpfs
SANDBOX_ID = "1000"  # the user and group ids inside (the files are still the grader's)


@dataclass(frozen=True)
class View:
    """What one sandbox shows of the host, and which namespaces it has of its own."""

    read_only: tuple[str, ...]  # host paths shown read-only at the same path
    writable: tuple[str, ...] = ()  # host paths shown writable at the same path
    links: Mapping[str, str] = field(default_factory=dict)  # path -> symlink target (/bin)
    own_network: bool = True  # loopback only; False: the parent sandbox's network
    own_pids: bool = True  # False: the parent sandbox's PID namespace and its /proc
    share_shm: bool = False  # the parent sandbox's /dev/shm (DDS shared memory)
    env: Mapping[str, str] = field(default_factory=dict)  # the whole environment inside
    keep_env: bool = False  # True: the caller's environment (a nested sandbox's node)
    unset: tuple[str, ...] = ()  # names taken out of the kept environment


def bwrap_argv(view: View, command: Sequence[str], *, bwrap: str = "bwrap") -> list[str]:
    """`command` run by bwrap in `view`; the order of mounts matters (tmpfs, then binds)."""
    argv = [bwrap, "--unshare-user", "--unshare-ipc", "--unshare-uts", "--unshare-cgroup-try"]
    if view.own_pids:
        argv.append("--unshare-pid")
    if view.own_network:
        argv.append("--unshare-net")
    # Never uid 0 inside: bwrap takes uid 0 for a privileged start (a nested one fails).
    argv += ["--uid", SANDBOX_ID, "--gid", SANDBOX_ID]
    argv += ["--die-with-parent", "--cap-drop", "ALL", "--hostname", "sandbox"]
    # A nested sandbox cannot mount a new /proc (the kernel refuses a proc mount
    # where the parent's is partly covered): it shows its parent's.
    argv += ["--proc", "/proc"] if view.own_pids else ["--ro-bind", "/proc", "/proc"]
    argv += ["--dev", "/dev"]
    argv += ["--bind", "/dev/shm", "/dev/shm"] if view.share_shm else ["--tmpfs", "/dev/shm"]
    argv += ["--tmpfs", "/tmp", "--tmpfs", "/home", "--dir", HOME, "--tmpfs", "/run"]
    for path, target in sorted(view.links.items()):
        argv += ["--symlink", target, path]
    binds = [(path, "--ro-bind") for path in view.read_only]
    binds += [(path, "--bind") for path in view.writable]
    for path, how in sorted(binds, key=lambda b: b[0].rstrip("/").count("/")):  # outer first
        argv += [how, path, path]
    argv += ["--chdir", SCRATCH]
    if not view.keep_env:
        argv.append("--clearenv")
    env = {} if view.keep_env else dict(view.env)
    for name, value in sorted({**env, "HOME": HOME, "TMPDIR": SCRATCH}.items()):
        argv += ["--setenv", name, value]
    for name in view.unset:
        argv += ["--unsetenv", name]
    return [*argv, "--", *command]
