"""The board's end of a paced serial line, in its own process, timing what arrives.

``python -m harness.bench.line_reader PTY SECONDS`` sends a SCAN request and
prints ``{"reads": [[t, n], ...], "data": "<hex>", "realtime": bool}``. A
process of its own, as the board's driver is, so the harness's GIL does not
delay the reads it times; under SCHED_FIFO where allowed (``realtime``), as
a UART interrupt would, so the times are the line's, not the scheduler's.
"""

from __future__ import annotations

import json
import os
import select
import sys
import time

from harness.serial_line.realtime_priority import raise_to_realtime

SCAN_REQUEST = bytes((0xA5, 0x20))
POLL_S = 0.05


def read_line(path: str, seconds: float) -> tuple[list[tuple[float, int]], bytes]:
    """Read from `path` until it closes or `seconds` pass; (time, size) of each read, the bytes."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    reads: list[tuple[float, int]] = []
    data = bytearray()
    try:
        os.write(fd, SCAN_REQUEST)
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            if not select.select([fd], [], [], min(POLL_S, left))[0]:
                continue
            try:
                chunk = os.read(fd, 65536)
            except BlockingIOError:
                continue
            except OSError:  # EIO: the harness closed its end
                break
            if not chunk:
                break
            reads.append((time.monotonic(), len(chunk)))
            data += chunk
    finally:
        os.close(fd)
    return reads, bytes(data)


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print("usage: python -m harness.bench.line_reader PTY SECONDS", file=sys.stderr)
        return 2
    realtime = raise_to_realtime()
    reads, data = read_line(argv[0], float(argv[1]))
    json.dump({"reads": reads, "data": data.hex(), "realtime": realtime}, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
