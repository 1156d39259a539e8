"""Keyboard teleop: teleop_twist_keyboard's keys, read from a real pseudo-terminal.

The pure state is driven key by key; the reader sits on the slave side of an
``os.openpty`` pair while the test types on the master side, as a terminal
would. Every wait is a bounded read, never a sleep.
"""

from __future__ import annotations

import contextlib
import os
import select
import termios
from collections.abc import Iterator

import pytest

from harness.cli import build_parser, flag_names
from harness.errors import ConfigError
from harness.live.teleop import (
    HELP,
    MOVE_KEYS,
    KeyboardTeleop,
    KeyReader,
    TeleopState,
)
from harness.option_names import speaking

WAIT = 2.0  # s: long enough for a pty under load; only ever spent when a test fails
QUIET = 0.05  # s: how long "nothing was typed" is watched


@pytest.fixture
def pty() -> Iterator[tuple[int, int]]:
    """(master, slave): the test types on master, the reader reads slave."""
    master, slave = os.openpty()
    yield master, slave
    for fd in (master, slave):
        with contextlib.suppress(OSError):
            os.close(fd)


def state(**limits: float) -> TeleopState:
    return TeleopState(limits.get("max_speed", 10.0), limits.get("max_turn", 10.0))


def pressed(keys: str, teleop: TeleopState | None = None) -> tuple[float, float]:
    teleop = teleop or state()
    for key in keys:
        teleop.press(key)
    return teleop.command


# --- the pure state ----------------------------------------------------------------------


def test_it_starts_stopped_at_teleop_twist_keyboards_speeds() -> None:
    teleop = state()
    assert teleop.command == (0.0, 0.0)
    assert teleop.status() == "speed 0.50 turn 1.00"


@pytest.mark.parametrize(
    ("key", "command"),
    [
        ("i", (0.5, 0.0)),
        (",", (-0.5, 0.0)),
        ("j", (0.0, 1.0)),
        ("l", (0.0, -1.0)),
        ("u", (0.5, 1.0)),
        ("o", (0.5, -1.0)),
        ("m", (-0.5, -1.0)),
        (".", (-0.5, 1.0)),
        ("k", (0.0, 0.0)),
    ],
)
def test_the_nine_keys_set_linear_and_angular(key: str, command: tuple[float, float]) -> None:
    assert state().press(key) == command


def test_k_stops_a_moving_robot() -> None:
    assert pressed("ik") == (0.0, 0.0)


@pytest.mark.parametrize("key", ["p", " ", "\r", "\x1b", "\x1a", "é", "K"])
def test_any_other_key_stops(key: str) -> None:
    assert pressed("u" + key) == (0.0, 0.0)


@pytest.mark.parametrize("sequence", ["\x1b[A", "\x1bOB", "\x1bi", ""])
def test_escape_sequences_change_nothing(sequence: str) -> None:
    teleop = state()
    teleop.press("i")
    assert teleop.press(sequence) == (0.5, 0.0)


def test_q_and_z_scale_both_and_the_robot_keeps_its_direction() -> None:
    teleop = state()
    assert pressed("uq", teleop) == pytest.approx((0.55, 1.1))
    assert teleop.status() == "speed 0.55 turn 1.10"
    assert pressed("zz", teleop) == pytest.approx((0.5 * 1.1 * 0.81, 1.1 * 0.81))


def test_w_and_x_scale_only_the_speed() -> None:
    assert pressed("uw") == pytest.approx((0.55, 1.0))
    assert pressed("ux") == pytest.approx((0.45, 1.0))


def test_e_and_c_scale_only_the_turn() -> None:
    assert pressed("ue") == pytest.approx((0.5, 1.1))
    assert pressed("uc") == pytest.approx((0.5, 0.9))


def test_the_scales_stop_at_the_robots_top_speeds() -> None:
    teleop = TeleopState(max_speed=0.4, max_turn=1.2)
    assert teleop.status() == "speed 0.40 (max) turn 1.00"  # the default 0.5 is too fast
    assert pressed("i" + "q" * 20, teleop) == (0.4, 0.0)
    assert teleop.status() == "speed 0.40 (max) turn 1.20 (max)"
    assert pressed("z", teleop) == pytest.approx((0.36, 0.0))
    assert teleop.status() == "speed 0.36 turn 1.08"


def test_shift_keys_go_sideways_which_the_robot_ignores() -> None:
    teleop = state()
    assert teleop.press("J") == (0.0, 0.0)
    assert teleop.ignored == (0.5, 0.0)
    assert teleop.press("U") == (0.5, 0.0)
    assert teleop.ignored == (0.5, 0.0)
    assert teleop.press("t") == (0.0, 0.0)
    assert teleop.ignored == (0.0, 0.5)
    assert teleop.press("i") == (0.5, 0.0)
    assert teleop.ignored == (0.0, 0.0)


def test_limits_must_be_positive() -> None:
    with pytest.raises(ValueError, match="max_speed"):
        TeleopState(0.0, 1.0)
    with pytest.raises(ValueError, match="turn"):
        TeleopState(1.0, 1.0, turn=float("nan"))


def test_the_help_names_the_layout_and_how_to_quit() -> None:
    for key in "uiojklm,.qzwxec":
        assert key in HELP
    assert "Ctrl-C" in HELP
    assert set("uiojklm,.") <= set(MOVE_KEYS)


# --- the terminal ------------------------------------------------------------------------


def test_keys_typed_come_out_one_by_one_and_drive_the_state(pty: tuple[int, int]) -> None:
    master, slave = pty
    teleop = state()
    with KeyReader(slave) as keys:
        os.write(master, b"i,jlkqi")
        typed = [keys.read(WAIT) for _ in range(7)]
        assert keys.read(QUIET) is None
    assert typed == list("i,jlkqi")
    commands = [teleop.press(key) for key in typed]
    expected = [(0.5, 0.0), (-0.5, 0.0), (0.0, 1.0), (0.0, -1.0), (0.0, 0.0), (0.0, 0.0)]
    assert commands == [*expected, pytest.approx((0.55, 0.0))]


def test_nothing_typed_is_none_once_the_timeout_passes(pty: tuple[int, int]) -> None:
    _, slave = pty
    with KeyReader(slave) as keys:
        assert keys.read(QUIET) is None
        assert keys.read(0.0) is None


def test_arrow_and_alt_keys_are_consumed_and_skipped(pty: tuple[int, int]) -> None:
    master, slave = pty
    with KeyReader(slave) as keys:
        os.write(master, b"\x1b[A\x1bOB\x1b[1;5C\x1b[15~\x1bii")  # up, down, Ctrl-right, F5, Alt+i
        assert keys.read(WAIT) == "i"
        assert keys.read(QUIET) is None


def test_an_arrow_key_alone_is_no_key(pty: tuple[int, int]) -> None:
    master, slave = pty
    with KeyReader(slave) as keys:
        os.write(master, b"\x1b[D")
        assert keys.read(0.3) is None


def test_esc_alone_is_a_key_and_stops(pty: tuple[int, int]) -> None:
    master, slave = pty
    with KeyReader(slave) as keys:
        os.write(master, b"\x1b")
        key = keys.read(WAIT)
    assert key == "\x1b"
    assert pressed("i" + key) == (0.0, 0.0)


def test_a_multibyte_character_is_one_key(pty: tuple[int, int]) -> None:
    master, slave = pty
    with KeyReader(slave) as keys:
        os.write(master, "éi".encode())
        assert [keys.read(WAIT), keys.read(WAIT)] == ["é", "i"]


def test_ctrl_c_raises_keyboard_interrupt_and_the_terminal_is_restored(
    pty: tuple[int, int],
) -> None:
    master, slave = pty
    before = termios.tcgetattr(slave)
    with pytest.raises(KeyboardInterrupt), KeyReader(slave) as keys:
        os.write(master, b"i\x03")
        assert keys.read(WAIT) == "i"
        keys.read(WAIT)
    assert termios.tcgetattr(slave) == before


def test_ctrl_c_right_after_esc_still_quits(pty: tuple[int, int]) -> None:
    master, slave = pty
    with KeyReader(slave) as keys:
        os.write(master, b"\x1b\x03")
        with pytest.raises(KeyboardInterrupt):
            keys.read(WAIT)


def test_inside_keys_are_unechoed_and_at_once_outside_as_before(pty: tuple[int, int]) -> None:
    _, slave = pty
    before = termios.tcgetattr(slave)
    with KeyReader(slave):
        inside = termios.tcgetattr(slave)
    assert termios.tcgetattr(slave) == before
    assert not inside[3] & (termios.ECHO | termios.ICANON | termios.ISIG)
    assert inside[1] & termios.OPOST == before[1] & termios.OPOST  # prints look as usual


def test_the_terminal_is_restored_when_the_session_fails(pty: tuple[int, int]) -> None:
    _, slave = pty
    before = termios.tcgetattr(slave)
    with pytest.raises(RuntimeError, match="the simulator broke"), KeyReader(slave):
        raise RuntimeError("the simulator broke")
    assert termios.tcgetattr(slave) == before


def test_keys_typed_before_the_session_are_dropped(pty: tuple[int, int]) -> None:
    master, slave = pty
    os.write(master, b"i\n")  # a line, so the canonical terminal reports it ready
    assert select.select([slave], [], [], WAIT)[0]
    with KeyReader(slave) as keys:
        assert keys.read(QUIET) is None


def test_a_terminal_that_hangs_up_ends_the_reading(pty: tuple[int, int]) -> None:
    master, slave = pty
    before = termios.tcgetattr(slave)
    with pytest.raises(EOFError), KeyReader(slave) as keys:
        os.close(master)
        keys.read(WAIT)
    with contextlib.suppress(termios.error):  # a hung-up terminal may refuse to be asked
        assert termios.tcgetattr(slave) == before


def test_reading_outside_the_with_block_is_a_bug(pty: tuple[int, int]) -> None:
    _, slave = pty
    with pytest.raises(RuntimeError, match="outside"):
        KeyReader(slave).read(0.0)


def test_a_pipe_is_not_a_terminal() -> None:
    read_end, write_end = os.pipe()
    try:
        with (
            speaking(flag_names(build_parser())),  # as the CLI names the option
            pytest.raises(ConfigError, match=r"^--teleop needs a terminal: file descriptor"),
        ):
            KeyReader(read_end)
    finally:
        os.close(read_end)
        os.close(write_end)


# --- both, for the simulator loop --------------------------------------------------------


def test_the_command_is_repeated_at_the_rate_and_sent_at_once_after_a_key(
    pty: tuple[int, int],
) -> None:
    master, slave = pty
    shown: list[str] = []
    with KeyReader(slave) as keys:
        teleop = KeyboardTeleop(keys, state(), rate_hz=10.0, show=shown.append)
        teleop.start()
        assert teleop.poll(0.0) == (0.0, 0.0)  # nothing sent yet: the stop goes out
        assert teleop.poll(0.05) is None
        assert teleop.poll(0.1) == (0.0, 0.0)
        os.write(master, b"i")
        assert teleop.poll(0.12, timeout=WAIT) == (0.5, 0.0)  # a key does not wait its turn
        assert teleop.poll(0.15) is None
        assert teleop.poll(0.25) == (0.5, 0.0)
        os.write(master, b"q")
        assert teleop.poll(0.26, timeout=WAIT) == pytest.approx((0.55, 0.0))
    assert shown == [HELP, "speed 0.50 turn 1.00", "speed 0.55 turn 1.10"]


def test_ctrl_c_reaches_the_simulator_loop(pty: tuple[int, int]) -> None:
    master, slave = pty
    with KeyReader(slave) as keys:
        teleop = KeyboardTeleop(keys, state(), show=lambda _: None)
        os.write(master, b"\x03")
        with pytest.raises(KeyboardInterrupt):
            teleop.poll(0.0, timeout=WAIT)
