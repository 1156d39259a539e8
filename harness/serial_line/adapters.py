"""What a serial port likely is, and whether this user may open it.

A device path says little on a bench with two adapters plugged in: the USB
id tells the chip (the A1M8's board is a CP2102), and a port this user may
not open is the first hour's most common failure; both are said with the fix.
"""

from __future__ import annotations

import grp
import os
import pwd
import re
import stat

_GROUP_RW = stat.S_IRGRP | stat.S_IWGRP

# USB ids of the common USB-UART chips (vendor:product, as pyserial prints them).
KNOWN_ADAPTERS: dict[str, str] = {
    "10C4:EA60": "Silicon Labs CP210x (the RPLIDAR A1's own adapter board uses one)",
    "1A86:7523": "WCH CH340 USB-UART",
    "1A86:7522": "WCH CH340K USB-UART",
    "1A86:55D4": "WCH CH9102 USB-UART",
    "0403:6001": "FTDI FT232R USB-UART",
    "0403:6010": "FTDI FT2232 USB-UART",
    "0403:6014": "FTDI FT232H USB-UART",
    "0403:6015": "FTDI FT230X/FT231X USB-UART",
    "067B:2303": "Prolific PL2303 USB-UART",
}
KNOWN_VENDORS: dict[str, str] = {
    "10C4": "Silicon Labs (CP210x family?)",
    "1A86": "WCH (CH34x family?)",
    "0403": "FTDI",
    "067B": "Prolific",
}


def likely_adapter(device: str, vid_pid: str | None) -> str:
    """A short guess at what `device` is, from its USB id or, without one, its name."""
    if vid_pid is not None:
        known = KNOWN_ADAPTERS.get(vid_pid.upper())
        if known:
            return known
        vendor = KNOWN_VENDORS.get(vid_pid.upper().split(":")[0])
        return f"{vendor} adapter" if vendor else "USB device (unknown chip)"
    name = os.path.basename(device)
    if re.fullmatch(r"ttyAMA\d+|ttyS\d+", name):
        return "built-in UART, not USB"
    return "not a USB adapter"


def access_problem(device: str) -> str | None:
    """None if this process may read and write `device`, else why not and the fix."""
    if os.access(device, os.R_OK | os.W_OK):
        return None
    try:
        st = os.stat(device)
    except OSError as err:
        return f"cannot see it: {os.strerror(err.errno or 0)}"
    try:
        group = grp.getgrgid(st.st_gid)
        user = pwd.getpwuid(os.getuid())
    except KeyError:
        return "no read/write permission (owner or group unknown to this system)"
    if st.st_mode & _GROUP_RW != _GROUP_RW:
        # Joining its group would not help: the group may not read and write it either.
        return (
            f"mode {stat.S_IMODE(st.st_mode):04o}, group {group.gr_name}: no group may open it; "
            'a udev rule with GROUP="dialout", MODE="0660" (docs/hil.md), then replug'
        )
    if user.pw_gid == group.gr_gid or user.pw_name in group.gr_mem:
        return (
            f"you are in group {group.gr_name}, this login session is not yet: "
            f"log out and in (or run `newgrp {group.gr_name}`)"
        )
    return (
        f"not in group {group.gr_name}: `sudo usermod -aG {group.gr_name} $USER`, then "
        "log out and in; or a udev rule (docs/hil.md)"
    )
