"""An unmodified RPLIDAR client in its own process, as a user's driver runs.

    python lidar_client.py LIBRARY PORT [--ask info,health] [--scans N] [--fossbot-agent]

LIBRARY is ``rplidar`` (whichever module of that name is on the path: PyPI
``rplidar`` 0.9.2, or ``rplidar-roboticia`` 0.9.5 when its folder comes
first on PYTHONPATH) or ``adafruit``. It asks what ``--ask`` names, reads
``--scans`` scans (0: until killed), sends STOP and disconnects, then
prints one JSON object: ``info``, ``health`` and ``scans`` (each a list of
[angle, distance]). ``--fossbot-agent`` makes the FOSSBot v2 agent's calls
around the scans instead (rplidar-roboticia's API).
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any


def _open(library: str, port: str) -> Any:
    if library == "adafruit":
        from adafruit_rplidar import RPLidar

        return RPLidar(None, port, timeout=3)
    from rplidar import RPLidar

    return RPLidar(port, timeout=3)


def _ask(lidar: Any, what: str) -> Any:
    if what == "info":
        return lidar.info if hasattr(type(lidar), "info") else lidar.get_info()
    return list(lidar.health if hasattr(type(lidar), "health") else lidar.get_health())


def _scans(lidar: Any, count: int, **options: Any) -> list[list[list[float]]]:
    """The first `count` scans as [angle, distance] pairs (0: read until killed)."""
    scans: list[list[list[float]]] = []
    for scan in lidar.iter_scans(**options):
        scans.append([[angle, distance] for _, angle, distance in scan])
        if len(scans) == count:
            break
    return scans


def plain(lidar: Any, asks: list[str], count: int) -> dict[str, Any]:
    """What the harness's tests ask: info and health if named, scans, STOP."""
    result = {what: _ask(lidar, what) for what in asks}
    result["scans"] = _scans(lidar, count)
    lidar.stop()
    return result


def fossbot_agent(lidar: Any, count: int) -> dict[str, Any]:
    """The FOSSBot v2 agent's call sequence (rplidar-roboticia): settle, reset, scan."""
    lidar.stop()
    lidar.stop_motor()
    time.sleep(0.3)
    lidar.clean_input()
    lidar.reset()
    time.sleep(2)
    lidar.clean_input()
    result = {"info": lidar.get_info()}
    result["scans"] = _scans(lidar, count, max_buf_meas=3000)
    lidar.stop()
    lidar.stop_motor()
    return result


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("library", choices=["rplidar", "adafruit"])
    parser.add_argument("port")
    parser.add_argument("--ask", default="", help="comma-separated: info, health")
    parser.add_argument("--scans", type=int, default=3)
    parser.add_argument("--fossbot-agent", action="store_true")
    args = parser.parse_args()
    lidar = _open(args.library, args.port)
    try:
        if args.fossbot_agent:
            result = fossbot_agent(lidar, args.scans)
        else:
            result = plain(lidar, [a for a in args.ask.split(",") if a], args.scans)
    finally:
        lidar.disconnect()
    print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
