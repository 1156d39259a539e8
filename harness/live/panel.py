"""The terminal's live panel: where the robot is, what it sees, what the node says.

A few lines, redrawn a few times a second by rich: the pose, the command
in force, the nearest return, the node's last status and warning, and the
judge's count with its latest disagreement. Node text is shown safely.
"""

from __future__ import annotations

import math

from rich.table import Table
from rich.text import Text

from harness.live.session import LiveState
from harness.safe_text import clip, for_terminal

STATUS_CHARS = 80  # of the node's status on the panel


def panel(state: LiveState, *, judging: bool) -> Table:
    """The panel for `state` (a rich renderable)."""
    table = Table.grid(padding=(0, 2))
    table.add_column(style="bold")
    table.add_column()
    pose = state.pose
    table.add_row("time", f"{state.t:7.1f} s")
    table.add_row(
        "pose", f"x {pose.x:6.2f} m   y {pose.y:6.2f} m   yaw {math.degrees(pose.yaw):6.1f} deg"
    )
    table.add_row("command", f"{state.command[0]:+.2f} m/s   {state.command[1]:+.2f} rad/s")
    if state.nearest is None:
        table.add_row("nearest", "nothing in range")
    else:
        distance, angle = state.nearest
        table.add_row("nearest", f"{distance:.2f} m at {angle:+.2f} rad")
    status = "-" if state.status is None else for_terminal(clip(state.status, STATUS_CHARS))
    table.add_row("status", Text(status))
    table.add_row("warning", _lamp(state.warning))
    if judging:
        verdict = Text(f"{state.judged} scans judged, {state.failed} failed")
        if state.last_failure:
            verdict.append("\n" + for_terminal(clip(state.last_failure, 200)), style="red")
        table.add_row("judge", verdict)
    return table


def _lamp(warning: bool | None) -> Text:
    if warning is None:
        return Text("- (none heard)")
    return Text("ON", style="bold red") if warning else Text("off", style="green")
