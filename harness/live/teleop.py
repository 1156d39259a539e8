"""Keyboard teleoperation for ``fossbot-hil sim --teleop``, with the lab's key layout.

The lab drives with ``teleop_twist_keyboard``; ``--teleop`` reads the same
keys in the simulator's terminal, so the lab's instructions hold as written.
The key logic (``TeleopState``, pure), the terminal (``KeyReader``) and the
repeat (``KeyboardTeleop``) are apart, so each is tested alone. Shift keys
and t/b (a holonomic robot's y and z) are kept as the tool sends them but
dropped, as the lab's Gazebo plugin does: ``U`` drives straight on.
"""

from __future__ import annotations

import codecs
import errno
import os
import select
import sys
import termios
import time
from collections.abc import Callable

from harness.errors import OptionError

# key -> (x, y, z, th), teleop_twist_keyboard's moveBindings (laid out as the keys are)
MOVE_KEYS: dict[str, tuple[int, int, int, int]] = {
    "u": (1, 0, 0, 1), "i": (1, 0, 0, 0), "o": (1, 0, 0, -1),
    "j": (0, 0, 0, 1), "k": (0, 0, 0, 0), "l": (0, 0, 0, -1),
    "m": (-1, 0, 0, -1), ",": (-1, 0, 0, 0), ".": (-1, 0, 0, 1),
    "U": (1, 1, 0, 0), "I": (1, 0, 0, 0), "O": (1, -1, 0, 0),
    "J": (0, 1, 0, 0), "L": (0, -1, 0, 0),
    "M": (-1, 1, 0, 0), "<": (-1, 0, 0, 0), ">": (-1, -1, 0, 0),
    "t": (0, 0, 1, 0), "b": (0, 0, -1, 0),
}  # fmt: skip
# key -> (factor on speed, factor on turn), teleop_twist_keyboard's speedBindings
SPEED_KEYS: dict[str, tuple[float, float]] = {
    "q": (1.1, 1.1), "z": (0.9, 0.9),  # speed and turn
    "w": (1.1, 1.0), "x": (0.9, 1.0),  # speed only
    "e": (1.0, 1.1), "c": (1.0, 0.9),  # turn only
}  # fmt: skip
DEFAULT_SPEED = 0.5  # m/s, teleop_twist_keyboard's default
DEFAULT_TURN = 1.0  # rad/s, teleop_twist_keyboard's default
REPEAT_RATE_HZ = 10.0  # well inside the robot's 0.5 s command timeout
ESCAPE_WAIT_S = 0.05  # an arrow key's bytes arrive together; a lone Esc has none after it
CTRL_C = "\x03"
ESC = "\x1b"
_LONGEST_SEQUENCE = 16  # bytes after Esc we consume at most: a garbled one cannot hang us

HELP = """\
Drive the FOSSBot with teleop_twist_keyboard's keys:
   u    i    o      forward: turning left, straight, turning right
   j    k    l      turn on the spot left, stop, turn right
   m    ,    .      backward: turning, straight, turning
q/z: speed and turn +/-10%   w/x: speed only   e/c: turn only
any other key: stop   Ctrl-C: quit
Shift (U I O J L M < >) and t/b move a holonomic robot sideways or up;
the FOSSBot's two wheels cannot, so it ignores that part."""


class TeleopState:
    """What the keys typed so far command: a direction times the speed and turn scales."""

    def __init__(
        self,
        max_speed: float,
        max_turn: float,
        speed: float = DEFAULT_SPEED,
        turn: float = DEFAULT_TURN,
    ) -> None:
        """`max_speed` (m/s) and `max_turn` (rad/s) cap the scales: q can never ask the
        robot for more than it can do (the real tool's speed_limit/turn_limit)."""
        for name, value in (("max_speed", max_speed), ("max_turn", max_turn)):
            if not value > 0:
                raise ValueError(f"{name} must be positive, got {value}")
        for name, value in (("speed", speed), ("turn", turn)):
            if not 0 < value < float("inf"):
                raise ValueError(f"{name} must be positive and finite, got {value}")
        self.max_speed = max_speed
        self.max_turn = max_turn
        self.speed = min(speed, max_speed)
        self.turn = min(turn, max_turn)
        self._direction = (0, 0, 0, 0)

    @property
    def command(self) -> tuple[float, float]:
        """(linear m/s, angular rad/s) in force: what the robot is asked to do."""
        x, _, _, th = self._direction
        return x * self.speed, th * self.turn

    @property
    def ignored(self) -> tuple[float, float]:
        """(sideways, up) m/s the real tool would also send; a differential drive drops them."""
        _, y, z, _ = self._direction
        return y * self.speed, z * self.speed

    def press(self, key: str) -> tuple[float, float]:
        """The command after `key`: a move key sets the direction, a speed key rescales
        it, any other single key stops. Not one character (an escape sequence, "")
        changes nothing: arrow keys are not part of the layout."""
        if len(key) != 1:
            return self.command
        if key in SPEED_KEYS:
            self._rescale(*SPEED_KEYS[key])
        else:
            self._direction = MOVE_KEYS.get(key, (0, 0, 0, 0))
        return self.command

    def _rescale(self, speed_factor: float, turn_factor: float) -> None:
        self.speed = min(self.speed * speed_factor, self.max_speed)
        self.turn = min(self.turn * turn_factor, self.max_turn)

    def status(self) -> str:
        """One line for the terminal: "speed 0.50 turn 1.00", "(max)" where capped."""
        speed = f"speed {self.speed:.2f}" + (" (max)" if self.speed >= self.max_speed else "")
        turn = f"turn {self.turn:.2f}" + (" (max)" if self.turn >= self.max_turn else "")
        return f"{speed} {turn}"


class KeyReader:
    """A terminal's keys one at a time, unechoed, for as long as the `with` lasts: cbreak,
    not raw, so the simulator's prints look as usual; signal keys read as keys (as in
    teleop_twist_keyboard), Ctrl-C raising KeyboardInterrupt from `read`."""

    def __init__(self, fd: int | None = None, *, escape_wait: float = ESCAPE_WAIT_S) -> None:
        """`fd` defaults to standard input; a ConfigError now if it is not a terminal,
        before the simulator has started anything."""
        self.fd = _stdin_fd() if fd is None else fd
        if not os.isatty(self.fd):
            where = "standard input" if self.fd == 0 else f"file descriptor {self.fd}"
            raise OptionError(
                "teleop",
                f"{{teleop}} needs a terminal: {where} is not one "
                "(run fossbot-hil sim {teleop} in a terminal, its input not piped or redirected)",
            )
        self.escape_wait = escape_wait
        self._saved: list | None = None

    def __enter__(self) -> KeyReader:
        if self._saved is not None:
            raise RuntimeError("this KeyReader is already in use")
        saved = termios.tcgetattr(self.fd)
        # TCSAFLUSH: keys typed while the world was loading do not drive the robot
        termios.tcsetattr(self.fd, termios.TCSAFLUSH, _cbreak(saved))
        self._saved = saved
        return self

    def __exit__(self, *exc: object) -> None:
        saved, self._saved = self._saved, None
        try:
            termios.tcsetattr(self.fd, termios.TCSADRAIN, saved)
        except termios.error as err:
            if err.args[0] != errno.EIO:  # EIO: the terminal hung up, nothing to restore
                raise

    def read(self, timeout: float) -> str | None:
        """The next key typed within `timeout` s, or None. Escape sequences (arrows,
        function keys, Alt+key) are consumed whole and skipped; a lone Esc is a key.
        Ctrl-C raises KeyboardInterrupt; a terminal that hung up raises EOFError."""
        if self._saved is None:
            raise RuntimeError("KeyReader.read outside its `with` block")
        deadline = time.monotonic() + max(timeout, 0.0)
        while True:
            key = self._key(max(deadline - time.monotonic(), 0.0))
            if key is not None and CTRL_C in key:  # also right after an Esc
                raise KeyboardInterrupt
            if key is None or not (key.startswith(ESC) and len(key) > 1):
                return key

    def _key(self, wait: float) -> str | None:
        first = self._byte(wait)
        if first is None:
            return None
        if first == ESC.encode():
            return ESC + self._escape_tail()
        return self._character(first)

    def _escape_tail(self) -> str:
        """What follows an Esc: a CSI (Esc [ ... final), SS3 (Esc O x) or Alt+key."""
        second = self._byte(self.escape_wait)
        if second is None:
            return ""
        if second == b"O":
            third = self._byte(self.escape_wait)
            return "O" + (third or b"").decode("latin-1")
        if second == b"[":
            return self._csi_tail()
        return self._character(second)

    def _csi_tail(self) -> str:
        tail = b"["
        while len(tail) < _LONGEST_SEQUENCE:
            byte = self._byte(self.escape_wait)
            if byte is None:
                break
            tail += byte
            if 0x40 <= byte[0] <= 0x7E and tail != b"[[":  # final byte (Esc [ [ A: Linux F1)
                break
        return tail.decode("latin-1")

    def _character(self, first: bytes) -> str:
        """One UTF-8 character starting with `first` (é is one key, not two)."""
        decoder = codecs.getincrementaldecoder("utf-8")("replace")
        text = decoder.decode(first)
        while not text:
            byte = self._byte(self.escape_wait)
            text = decoder.decode(byte or b"", final=byte is None)
        return text

    def _byte(self, wait: float) -> bytes | None:
        ready, _, _ = select.select([self.fd], [], [], wait)
        if not ready:
            return None
        try:
            data = os.read(self.fd, 1)
        except OSError as err:
            if err.errno != errno.EIO:
                raise
            data = b""
        if not data:
            raise EOFError("the terminal closed")
        return data


class KeyboardTeleop:
    """The keyboard as the simulator's driver: keys in, the command in force out, at once
    and again every 1/`rate_hz` s, as the robot stops when commands stop coming."""

    def __init__(
        self,
        reader: KeyReader,
        state: TeleopState,
        *,
        rate_hz: float = REPEAT_RATE_HZ,
        show: Callable[[str], None] = print,
    ) -> None:
        if not rate_hz > 0:
            raise ValueError(f"rate_hz must be positive, got {rate_hz}")
        self.reader = reader
        self.state = state
        self.period = 1.0 / rate_hz
        self.show = show
        self._sent_at: float | None = None

    def start(self) -> None:
        """Show the keys and the speeds, as teleop_twist_keyboard does when it starts."""
        self.show(HELP)
        self.show(self.state.status())

    def poll(self, now: float, timeout: float = 0.0) -> tuple[float, float] | None:
        """(m/s, rad/s) to send at `now`, or None while the last one sent is fresh; takes
        every key typed (waiting at most `timeout` s for the first)."""
        typed = False
        key = self.reader.read(timeout)
        while key is not None:
            typed = True
            self.state.press(key)
            if key in SPEED_KEYS:
                self.show(self.state.status())
            key = self.reader.read(0.0)
        fresh = self._sent_at is not None and now - self._sent_at < self.period
        if fresh and not typed:
            return None
        self._sent_at = now
        return self.state.command


def _stdin_fd() -> int:
    """Standard input's descriptor; a ConfigError if there is none (closed, replaced)."""
    try:
        return sys.stdin.fileno()
    except (AttributeError, ValueError, OSError) as err:
        raise OptionError(
            "teleop", "{teleop} needs a terminal: standard input has no file descriptor"
        ) from err


def _cbreak(attrs: list) -> list:
    """`attrs` with keys delivered at once, unechoed, Ctrl-C/Ctrl-S read as keys."""
    mode = [*attrs[:6], list(attrs[6])]
    mode[0] &= ~termios.IXON  # Ctrl-S would freeze the output until Ctrl-Q
    mode[3] &= ~(termios.ECHO | termios.ICANON | termios.ISIG | termios.IEXTEN)
    mode[6][termios.VMIN] = 1
    mode[6][termios.VTIME] = 0
    return mode
