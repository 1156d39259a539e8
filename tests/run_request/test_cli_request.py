"""The command line's options come from the run request's table, and the request knows
which the user typed (no second parse)."""

from __future__ import annotations

import pytest

from harness.cli import build_parser
from harness.commands.arguments import request_of
from harness.errors import ConfigError
from harness.run_request import OPTIONS


def test_the_request_knows_what_was_typed() -> None:
    """Typed options, whatever their value (a default typed again counts), and no others."""
    args = build_parser().parse_args(["run", "--seed", "3", "--timeout", "1", "--realtime"])
    assert args.given == {"seed", "timeout", "realtime"}
    request = request_of(args)
    assert request.given == {"seed", "scan_timeout", "realtime"}
    assert (request.seed, request.scan_timeout, request.realtime) == (3, 1.0, True)
    assert request_of(build_parser().parse_args(["run"])).given == frozenset()


def test_run_has_every_row_with_a_flag() -> None:
    """`run` takes each of the table's options that has a command-line flag."""
    args = build_parser().parse_args(["run"])
    missing = [row.cli for row in OPTIONS if row.cli and not hasattr(args, row.dest)]
    assert not missing


def test_the_requests_checks_speak_in_flags() -> None:
    args = build_parser().parse_args(
        ["run", "--link", "rplidar", "--board-command", "true", "--port", "/dev/null"]
    )
    with pytest.raises(ConfigError, match="^--board-command runs the board's software .* --port"):
        request_of(args)
