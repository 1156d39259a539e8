"""The run request: one table of options, read and checked once, each error worded with the
caller's names for the options (pure: no rclpy, no pybullet)."""

from __future__ import annotations

import pytest

from harness.links.base import LinkOptions
from harness.run_request import OPTIONS, OptionError, RunRequest
from harness.run_request.table import names


def _refused(values: dict[str, object], caller: str = "cli") -> str:
    with pytest.raises(OptionError) as err:
        RunRequest.of(values)
    return err.value.render(names(caller))


def test_every_row_is_one_key_with_a_request_field() -> None:
    """A new option is one row: its key is a field of the request, named once per caller."""
    keys = [row.key for row in OPTIONS]
    assert len(keys) == len(set(keys))
    assert set(keys) <= set(RunRequest.__dataclass_fields__)
    flags = [row.cli for row in OPTIONS if row.cli]
    assert len(flags) == len(set(flags))


def test_defaults_give_the_links_own_defaults() -> None:
    """An empty request is the reference node over the default link options."""
    assert RunRequest.of({}).link_options() == LinkOptions()


def test_values_from_text_and_typed_values_read_alike() -> None:
    """A command line's text and hil.run's typed values make the same request."""
    typed = RunRequest.of({"seed": 7, "scan_timeout": 2, "params": ["a:=1"], "domain_id": 3})
    text = RunRequest.of({"seed": "7", "scan_timeout": "2", "params": "a:=1", "domain_id": "3"})
    assert typed == text
    assert typed.link_options().params == ("a:=1",) and typed.link_options().scan_timeout == 2.0
    assert typed.run_settings().seed == 7


def test_faults_text_becomes_a_list() -> None:
    assert RunRequest.of({"faults": "noisy,drop(rate=0.1)"}).run_settings().faults == [
        "noisy",
        "drop(rate=0.1)",
    ]
    assert RunRequest.of({}).run_settings().faults is None


@pytest.mark.parametrize(
    ("values", "cli", "hil"),
    [
        ({"seed": "x"}, "--seed must be a whole number, got 'x'", "--hil-seed must be"),
        ({"seed": 2**32}, "--seed must be a whole number in 0..2**32-1", "--hil-seed must"),
        ({"scan_timeout": 0}, "--timeout must be a positive number", "--hil-timeout must"),
        ({"warning_when_clear": "yes"}, "give optional or required, got 'yes'", "give optional"),
        (
            {"node": "x", "package": "p"},
            "--node and --package: give one or the other",
            "--hil-node and --hil-package: give one or the other",
        ),
        ({"package": "p"}, "--package and --executable go together", "--hil-package and --hil-"),
        (
            {"link": "inprocess", "params": ["a:=1"]},
            "--param needs a link that runs a node, not --link inprocess",
            "--hil-param needs a link that runs a node, not --hil-link inprocess",
        ),
        (
            {"link": "ros2", "board_commands": ["true"]},
            "--board-command needs --link rplidar or ldlidar, not ros2",
            "needs --hil-link rplidar or ldlidar, not ros2",
        ),
        (
            {"board_commands": ["true"], "port": "/dev/null"},
            "--board-command runs the board's software on the virtual board; with --port",
            "with --hil-port the physical board runs its own",
        ),
        (
            {"link": "ros2", "processor": "m:f"},
            "--processor needs --link inprocess (the ros2 link runs a node)",
            "needs --hil-link inprocess",
        ),
        ({"port": "/nonexistent/ttyUSB9"}, "--port /nonexistent/ttyUSB9: no such device", "--hil-"),
        ({"link": "serial"}, "unknown link 'serial' (known: inprocess, ldlidar", "unknown link"),
    ],
)
def test_each_problem_is_said_once_in_each_callers_words(
    values: dict[str, object], cli: str, hil: str
) -> None:
    """One check, the CLI's flags or the plugin's --hil-* options in its message."""
    assert cli in _refused(values, "cli")
    assert hil in _refused(values, "hil")


def test_a_value_problem_names_hil_runs_keyword() -> None:
    """hil.run's keywords (scan_timeout=) name the option where the reader's text does not."""
    assert _refused({"scan_timeout": "0"}, "run").startswith("scan_timeout must be a positive")
    with pytest.raises(OptionError) as err:
        RunRequest.of({"warning_when_clear": "yes"})
    assert err.value.render(names("run"), subject=True).startswith("warning_when_clear: give")


def test_braces_in_a_value_are_shown_not_formatted() -> None:
    """A value quoted in a message is text, never part of the template."""
    assert "'{seed}'" in _refused({"seed": "{seed}"})


def test_typed_options_win_over_a_files() -> None:
    """with_values fills in only what the user did not give (the command line wins)."""
    typed = RunRequest.of({"seed": 3, "threshold": 0.4}, given={"seed"})
    merged = typed.with_values({"seed": 9, "threshold": 0.6, "scan_timeout": 2.0})
    assert (merged.seed, merged.threshold, merged.scan_timeout) == (3, 0.6, 2.0)


def test_an_unknown_key_is_refused() -> None:
    assert "unknown option 'speed'" in _refused({"speed": 1})
