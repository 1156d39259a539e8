"""Modem lines on a pty: unmodified pyserial clients set DTR/RTS, and the emulator hears them.

Each client is a real Python process run with the port's client
environment (the modem shim on PYTHONPATH, the port listed in
FOSSBOT_HIL_MODEM_LINES), on a real pty; nothing is mocked. Without that
environment the same client fails with ENOTTY, as it does on any pty.
"""

from __future__ import annotations

import os
import select
import shutil
import socket
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from harness.devices.revolution import Sample
from harness.devices.rplidar import RplidarDevice
from harness.serial_line.modem_lines import (
    ENV_VAR,
    SHIM_FOLDER,
    ModemLines,
    client_environment,
    listing_item,
)
from harness.serial_line.ports import PtyPort
from harness.serial_line.server import DeviceServer

pytestmark = pytest.mark.timeout(30)

CLIENT_TIMEOUT_S = 10.0


def run_python(code: str, *args: str, env: dict[str, str] | None = None) -> str:
    """`python -c code args...` in its own process; its stdout (it must exit 0)."""
    done = subprocess.run(
        [sys.executable, "-c", code, *args],
        env={**os.environ, **(env or {})},
        capture_output=True,
        text=True,
        timeout=CLIENT_TIMEOUT_S,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def watched(port: PtyPort) -> list[tuple[str, bool]]:
    """The modem-line changes the port reports from now on."""
    changes: list[tuple[str, bool]] = []
    port.on_modem_change = lambda line, asserted: changes.append((line, asserted))
    return changes


# -- the variable, the socket ---------------------------------------------------


def test_client_environment_puts_the_shim_and_the_port_first_and_keeps_the_rest() -> None:
    """Existing PYTHONPATH and listing are kept, behind ours; the shim is not listed twice."""
    shim = str(SHIM_FOLDER)
    environ = {"PYTHONPATH": f"/opt/ros/lib{os.pathsep}{shim}", ENV_VAR: "/dev/pts/9"}
    env = client_environment("/dev/pts/3", "/tmp/m/lines", environ)
    assert env == {
        "PYTHONPATH": f"{shim}{os.pathsep}/opt/ros/lib",
        ENV_VAR: f"/dev/pts/3=/tmp/m/lines{os.pathsep}/dev/pts/9",
    }
    assert client_environment("/dev/pts/3", None, {}) == {"PYTHONPATH": shim, ENV_VAR: "/dev/pts/3"}
    assert [p.name for p in SHIM_FOLDER.glob("*.py")] == ["sitecustomize.py"]  # nothing else
    with pytest.raises(ValueError, match="cannot hold"):
        listing_item(f"/dev/odd{os.pathsep}name", None)


def test_modem_lines_keep_the_last_level_and_clean_up() -> None:
    """Datagrams in order, the last level kept, other bytes ignored; a private folder, removed."""
    lines = ModemLines()
    folder = Path(lines.path).parent
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    assert (lines.dtr, lines.rts) == (None, None)
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as sender:
        for message in (b"DTR 1", b"noise", b"RTS 0", b"DTR 0", b"DTR 0", b"XYZ 1"):
            sender.sendto(message, lines.path)
    assert lines.poll() == [("dtr", True), ("rts", False), ("dtr", False)]
    assert lines.poll() == []
    assert lines.hang_up() == []  # both already low
    lines.close()
    lines.close()
    assert not folder.exists()


# -- the shim in a real client process --------------------------------------------

SET_LINES = """
import serial, sys
port = serial.Serial(sys.argv[1])   # pyserial asserts DTR and RTS as it opens
port.dtr = False
port.rts = False
print(port.cts, port.dsr, port.ri, port.cd)
port.setDTR(True)
port.close()
"""


def test_a_pyserial_client_sets_dtr_and_rts_on_a_listed_pty() -> None:
    """Every change arrives in order; inputs read False; closing drops DTR, as on a tty."""
    with PtyPort() as port:
        changes = watched(port)
        out = run_python(SET_LINES, port.slave_path, env=port.client_environment())
        assert out.split() == ["False"] * 4
        assert port.dtr_asserted() is False  # the client closed: its DTR dropped
        assert changes == [
            ("dtr", True),
            ("rts", True),
            ("dtr", False),
            ("rts", False),
            ("dtr", True),
            ("dtr", False),  # the hang-up
        ]


CALL_TIME = f"""
import errno, os, serial, sys
port = serial.Serial(sys.argv[1])
os.environ.pop({ENV_VAR!r})
try:
    port.dtr = True
except OSError as err:
    print("dtr", errno.errorcode[err.errno])
try:
    port.cts
except OSError as err:
    print("cts", errno.errorcode[err.errno])
os.environ[{ENV_VAR!r}] = sys.argv[1]  # listed, with no socket: succeeds, goes nowhere
port.rts = False
print("rts", port.rts)
"""


def test_unlisted_ports_fail_as_before_and_the_listing_is_read_at_each_call() -> None:
    """Taken off the listing, DTR and CTS fail with ENOTTY again; listed with no socket,
    a change succeeds and reaches nobody."""
    with PtyPort() as port:
        changes = watched(port)
        out = run_python(CALL_TIME, port.slave_path, env=port.client_environment())
        assert out.splitlines() == ["dtr ENOTTY", "cts ENOTTY", "rts False"]
        port.dtr_asserted()
        assert changes == [("dtr", True), ("rts", True), ("dtr", False), ("rts", False)]


USER_SITE = 'print("user sitecustomize ran")\n'
AT_START = """
import sys, sitecustomize
print(sorted({"serial", "socket"} & set(sys.modules)))
print(sum(hasattr(f, "_fossbot_hil_modem_lines") for f in sys.meta_path), "finder")
print(sitecustomize.__file__)
"""


def test_the_shim_imports_nothing_heavy_and_runs_the_next_sitecustomize(tmp_path) -> None:
    """A user's sitecustomize after it still runs, once, even with a second copy of the
    shim between them; serial and socket are not imported at start-up."""
    copy = tmp_path / "copy"
    copy.mkdir()
    shutil.copy(SHIM_FOLDER / "sitecustomize.py", copy)
    user = tmp_path / "user"
    user.mkdir()
    (user / "sitecustomize.py").write_text(USER_SITE)
    path = os.pathsep.join([str(copy), str(user)])
    env = client_environment("/dev/null", None, {"PYTHONPATH": path})
    out = run_python(AT_START, env=env).splitlines()
    assert out == ["user sitecustomize ran", "[]", "1 finder", str(user / "sitecustomize.py")]


def test_without_the_environment_a_pyserial_client_fails_on_a_pty() -> None:
    """The same client, not given the environment: its first setDTR fails (ENOTTY)."""
    with PtyPort() as port:
        done = subprocess.run(
            [sys.executable, "-c", "import rplidar, sys; rplidar.RPLidar(sys.argv[1])"]
            + [port.slave_path],
            capture_output=True,
            text=True,
            timeout=CLIENT_TIMEOUT_S,
        )
    assert done.returncode != 0
    assert "[Errno 25] Inappropriate ioctl for device" in done.stderr, done.stderr


# -- the emulator follows the motor line --------------------------------------------

RPLIDAR_CLIENT = """
import sys
from rplidar import RPLidar   # PyPI rplidar 0.9.2, unmodified
lidar = RPLidar(sys.argv[1], timeout=3)   # opens, starts the motor (setDTR(False))
lidar.stop_motor()   # setDTR(True)
print("stopped", flush=True)
sys.stdin.readline()   # until the test saw the motor stop
for n, scan in enumerate(lidar.iter_scans()):   # start_motor, GET_HEALTH, SCAN
    print(len(scan), flush=True)
    if n == 2:
        break
lidar.stop()
lidar.disconnect()
"""


def revolution(k: int, n: int = 90) -> list[Sample]:
    return [Sample(i * 360.0 / n, 500.0 + 10.0 * k + i, 47) for i in range(n)]


def read_line(client: subprocess.Popen, timeout: float) -> str:
    """The client's next stdout line, waited for at most `timeout` s."""
    assert client.stdout is not None
    ready = select.select([client.stdout], [], [], timeout)[0]
    assert ready, f"no line from the client in {timeout} s"
    return client.stdout.readline()


def test_the_rplidar_package_drives_the_emulated_motor_over_dtr() -> None:
    """A bare A1 (no PWM input: only DTR runs its motor) on a pty: rplidar 0.9.2's
    stop_motor stops it, iter_scans starts it, and every pushed revolution is read."""
    events: list = []
    with PtyPort() as port:
        device = RplidarDevice(pwm_controls_motor=False)
        with DeviceServer(device, port, listener=events.append) as server:
            client = subprocess.Popen(
                [sys.executable, "-c", RPLIDAR_CLIENT, port.slave_path],
                env={**os.environ, **port.client_environment()},
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            try:
                assert read_line(client, CLIENT_TIMEOUT_S) == "stopped\n"
                assert server.wait_until(lambda d: not d.motor_on, 5.0)
                client.stdin.write("go\n")
                client.stdin.flush()
                assert server.wait_until(lambda d: d.mode == "scan" and d.motor_on, 5.0)
                for k in range(3):
                    server.send_revolution(revolution(k), k)
                    assert read_line(client, 3.0).strip() == "90"
                assert client.wait(CLIENT_TIMEOUT_S) == 0, client.stderr.read()
            finally:
                client.kill()
                client.communicate(timeout=CLIENT_TIMEOUT_S)
    motor = [event.note for event in events if getattr(event, "kind", "") == "motor"]
    off = motor.index("board's DTR asserted: motor off")
    assert "board's DTR deasserted: motor on" in motor[off + 1 :], motor
