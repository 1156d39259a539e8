"""The FOSSBot v2 robot agent's LIDAR service, as the robot runs it, for tests.

The lab robot's Raspberry Pi runs an agent with no ROS (LRMPUT/fossbot-ros2-bridge,
robot_agent/fossbot_agent.py): it serves complete LIDAR revolutions to one TCP
client at a time, each as a JSON line ``{"t": ..., "pts": [[angle_deg,
dist_mm], ...]}``, and opens the RPLIDAR A1M8 afresh for each client with
rplidar-roboticia 0.9.5 (the module ``rplidar`` on PYTHONPATH): ``RPLidar``,
``stop``, ``stop_motor``, 0.3 s, ``clean_input``, ``reset``, 2 s,
``clean_input``, ``get_info``, then ``iter_scans(max_buf_meas=3000)``. That
library reads with no timeout: a device that falls silent hangs it for ever.
This script does exactly that, unchanged by the harness; only the device path
and the TCP port are arguments (and a file that its log lines also go to, for
the tests to read). It logs what the robot's agent prints, one line each,
flushed.
"""

from __future__ import annotations

import argparse
import json
import socket
import time

from rplidar import RPLidar  # rplidar-roboticia 0.9.5

LOG_FILE: list[str] = []  # --log: where the lines go too


def log(text: str) -> None:
    line = f"[agent] {text}"
    print(line, flush=True)
    for path in LOG_FILE:
        with open(path, "a", encoding="utf-8") as out:
            out.write(line + "\n")


def open_lidar(device: str, attempts: int = 3) -> RPLidar | None:
    """Open the LIDAR, recovering from a dirty serial state (the agent's own sequence)."""
    for attempt in range(1, attempts + 1):
        lidar = None
        try:
            lidar = RPLidar(device)
            for step in (lidar.stop, lidar.stop_motor):
                try:
                    step()
                except Exception as err:  # noqa: BLE001 - the agent ignores these
                    log(f"ignored {step.__name__}: {err}")
            time.sleep(0.3)
            lidar.clean_input()
            lidar.reset()
            time.sleep(2.0)  # an A1 reset takes about two seconds
            lidar.clean_input()
            info = lidar.get_info()
            log(f"lidar ready: {info}")
            return lidar
        except Exception as err:  # noqa: BLE001 - as the agent: report and retry
            log(f"lidar open attempt {attempt}/{attempts} failed: {err}")
            if lidar is not None:
                try:
                    lidar.disconnect()
                except Exception:  # noqa: BLE001
                    pass
            time.sleep(1.5)
    return None


def stream(connection: socket.socket, device: str) -> None:
    """Serve revolutions to one client until it goes or the LIDAR fails."""
    connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    lidar = open_lidar(device)
    try:
        if lidar is None:
            return
        for scan in lidar.iter_scans(max_buf_meas=3000):
            payload = {"t": time.time(), "pts": [[round(a, 2), round(d, 1)] for _, a, d in scan]}
            connection.sendall((json.dumps(payload) + "\n").encode())
    except Exception as err:  # noqa: BLE001 - as the agent: the client reconnects
        log(f"lidar stopped: {err}")
    finally:
        if lidar is not None:
            for step in (lidar.stop, lidar.stop_motor, lidar.disconnect):
                try:
                    step()
                except Exception:  # noqa: BLE001
                    pass
        connection.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", required=True, help="the LIDAR's serial device")
    parser.add_argument("--lidar-port", type=int, required=True, help="TCP port to serve on")
    parser.add_argument("--log", help="also append the log lines to this file")
    args = parser.parse_args()
    if args.log:
        LOG_FILE.append(args.log)
    server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    server.bind(("127.0.0.1", args.lidar_port))
    server.listen(1)
    server.settimeout(0.5)
    log(f"up: lidar tcp/{args.lidar_port}")
    try:
        while True:
            try:
                connection, address = server.accept()
            except TimeoutError:
                continue
            log(f"lidar client {address}")
            stream(connection, args.device)
    except KeyboardInterrupt:
        log("shutting down")
    finally:
        server.close()


if __name__ == "__main__":
    main()
