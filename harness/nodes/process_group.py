"""Stopping a child's whole process group, and waiting (bounded) until it is gone.

Student code runs in groups of its own, so what it starts stops with it; SIGKILL is
delivered, not instant, so "stopped" means nothing in the group runs any more."""

from __future__ import annotations

import contextlib
import os
import select
import time

__all__ = ["group_members", "signal_group", "wait_group_gone"]


def signal_group(pgid: int, sig: int) -> None:
    """Send `sig` to every process of group `pgid`; a group already gone is fine."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pgid, sig)


def group_members(pgid: int) -> list[int]:
    """Pids still running (not zombies) in process group `pgid`, from /proc."""
    members = []
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            with open(f"/proc/{entry.name}/stat", "rb") as stat:
                fields = stat.read().rsplit(b")", 1)[1].split()
        except OSError:
            continue
        # After the command name: state, ppid, pgrp, ...
        if int(fields[2]) == pgid and fields[0] not in (b"Z", b"X"):
            members.append(int(entry.name))
    return members


def wait_group_gone(pgid: int, timeout: float) -> None:
    """Wait, bounded, until nothing in the group runs (each member through a pidfd, readable
    when it dies, whoever reaps it)."""
    deadline = time.monotonic() + timeout
    for pid in group_members(pgid):
        try:
            fd = os.pidfd_open(pid)
        except OSError:  # gone already
            continue
        try:
            select.select([fd], [], [], max(0.0, deadline - time.monotonic()))
        finally:
            os.close(fd)
