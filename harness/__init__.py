"""fossbot-hil: scenario and hardware-in-the-loop tests for the FOSSBot LIDAR lab.

The packages follow a scan's way (docs/architecture.md draws the map):
``scenario`` says what to simulate, ``sim`` makes the true ranges,
``faults`` spoils them, ``links`` carry them to the software under test
(``nodes``, ``ros``; ``devices`` and ``serial_line`` on a serial line),
``judge`` weighs the answers, ``runner`` drives all of it, and ``record``
and ``report`` write what people read. ``commands``, ``pytest_plugin``,
``grading`` and ``bench`` are the ways in. Pure logic (``lidar``,
``faults``, ``judge``, ``scenario``) imports neither rclpy nor pybullet.
"""

import time as _time
from collections.abc import Callable
from importlib import import_module
from typing import Any

__version__ = "0.1.0"
IMPORTED_AT = _time.monotonic()  # a command's clock starts here (harness.report.wall_clock)


def lazy_exports(package: str, exports: dict[str, str]) -> Callable[[str], Any]:
    """A package's module ``__getattr__`` (PEP 562) for its exported names.

    Each name loads its module on first use, so importing one small module
    of a package (a pure helper) does not import the rest (pybullet, rclpy).
    `exports` maps a name to the module, within `package`, that defines it.
    """

    def __getattr__(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(import_module(f"{package}.{module}"), name)

    return __getattr__
