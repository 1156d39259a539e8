"""How a LIDAR device sits on the robot: where its own zero points, which way it counts.

A ``Scan`` is in the scan frame (REP-103: counter-clockwise, 0 ahead); a
spinning LIDAR counts degrees clockwise from its own zero (on the FOSSBot
v2 the A1's points right: ``yaw_deg = -90``), the other way round when
mounted upside down (``mirrored``). A board driver mapping ``theta`` to
``(-theta if invert else theta) + angle_offset_deg`` shows the scan frame
exactly when ``invert = not mirrored`` and ``angle_offset_deg = yaw_deg``.
"""

from __future__ import annotations

from dataclasses import dataclass

from harness.errors import OptionError

__all__ = ["FORWARD", "LidarMount", "parse_mount"]

FORWARD_WORDS = ("forward", "generic")
MODEL_WORD = "model"


@dataclass(frozen=True)
class LidarMount:
    """The device's zero and sense of rotation in the robot's scan frame."""

    yaw_deg: float = 0.0  # where the device's 0 degrees points: CCW from forward, degrees
    mirrored: bool = False  # True: device angles run counter-clockwise seen from above

    def driver_settings(self) -> tuple[bool, float]:
        """(invert, angle_offset_deg) that turn this device's angles back into the scan frame."""
        return (not self.mirrored, self.yaw_deg)

    def describe(self) -> str:
        """For messages: 'zero at -90 deg (to the right), clockwise'."""
        where = {0.0: "straight ahead", 90.0: "to the left", -90.0: "to the right"}
        yaw = ((self.yaw_deg + 180.0) % 360.0) - 180.0
        side = where.get(yaw, "")
        sense = "counter-clockwise (mirrored)" if self.mirrored else "clockwise"
        return f"zero at {yaw:g} deg{f' ({side})' if side else ''}, {sense}"

    def option_text(self) -> str:
        """The `--lidar-mount` value that gives this mount."""
        return f"{self.yaw_deg:g}" + (",mirrored" if self.mirrored else "")


FORWARD = LidarMount()  # a generic mount: zero straight ahead, clockwise


def parse_mount(text: str) -> LidarMount | None:
    """`--lidar-mount`: 'model' (None: what the robot model says), 'forward', or
    'DEG[,mirrored]' (the device's zero, CCW from forward). OptionError when neither."""
    value = text.strip().lower()
    if value == MODEL_WORD:
        return None
    if value in FORWARD_WORDS:
        return FORWARD
    yaw_text, _, flag = value.partition(",")
    if flag not in ("", "mirrored"):
        raise OptionError.saying(
            "lidar_mount", f"{text[:40]!r}: after the angle only ',mirrored' may follow"
        )
    try:
        yaw = float(yaw_text)
    except ValueError:
        yaw = float("nan")
    if not -360.0 <= yaw <= 360.0:  # also refuses nan and inf
        raise OptionError.saying(
            "lidar_mount",
            f"{text[:40]!r}: give model, forward, or the angle of the device's zero in degrees "
            "(-360..360, counter-clockwise from forward), e.g. -90 or 180,mirrored",
        )
    return LidarMount(yaw_deg=yaw + 0.0, mirrored=flag == "mirrored")
