"""`fossbot-hil`: list scenarios and run them against a node or a board.

Exit codes: 0 every expectation held, 1 some failed, 2 usage or
configuration error (one line on stderr naming the file or field).
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Sequence

from rich.console import Console

from harness import __version__
from harness.commands import command_modules
from harness.commands.arguments import expand_arguments
from harness.errors import ConfigError, HarnessError, Interrupted
from harness.nodes.quick_exit import exit_now
from harness.option_names import speaking
from harness.run_request.table import names

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2


class _Parser(argparse.ArgumentParser):
    """argparse, but usage errors are one line and exit 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise ConfigError(f"{message} (see '{self.prog} --help')")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="fossbot-hil", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for module in command_modules():
        description = getattr(module, "DESCRIPTION", module.HELP)  # `X --help`'s first line
        module.add_arguments(
            commands.add_parser(module.NAME, help=module.HELP, description=description)
        )
    return parser


def _print_error(message: str) -> None:
    """One error on stderr; it may quote a node's text (topic names), so shown safely."""
    from harness.safe_text import clip, for_terminal

    print(f"fossbot-hil: error: {for_terminal(clip(message))}", file=sys.stderr)


def _interrupt_on_sigterm() -> None:
    """SIGTERM ends a run like Ctrl-C does: links close, nodes are stopped and reaped."""

    def handler(signum: int, frame: object) -> None:
        raise Interrupted(signum)

    signal.signal(signal.SIGTERM, handler)


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; return its exit code (for tests and embedding)."""
    console = Console(highlight=False)
    if not console.is_terminal:
        console = Console(highlight=False, width=200)  # files and pipes: no wrapping
    try:
        parser = build_parser()
        with speaking(flag_names(parser)):  # lower layers' messages name options as flags
            return _run(parser, argv, console)
    except ConfigError as err:
        _print_error(str(err))
        return EXIT_USAGE
    except KeyboardInterrupt as err:  # 130 for Ctrl-C, 143 for SIGTERM, as shells expect
        stop = Interrupted.of(err)
        summary = f": {stop.summary}" if stop.summary else ""
        _print_error(f"interrupted by {stop.name}{summary}")
        return stop.exit_code
    except HarnessError as err:
        _print_error(str(err))
        return EXIT_FAILED


def flag_names(parser: argparse.ArgumentParser) -> dict[str, str]:
    """Each option key as the CLI spells it: the run options' flags (the table's), and
    every other flag of every command by its argparse name."""
    found: dict[str, str] = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                found.update(flag_names(sub))
        flags = [s for s in action.option_strings if s.startswith("--")]
        if flags and action.dest not in found:
            found[action.dest] = max(flags, key=len)
    return {**found, **names("cli")}


def _run(parser: argparse.ArgumentParser, argv: Sequence[str] | None, console: Console) -> int:
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return EXIT_USAGE
    expand_arguments(args)  # ~ and $VAR in paths and commands, as a shell would
    args.given = getattr(args, "given", frozenset())  # noted as parsed (arguments.add_row)
    handlers = {m.NAME: m.run for m in command_modules()}
    return handlers[args.command](args, console)


def entry() -> None:
    """The `fossbot-hil` console script (it exits without the interpreter's teardown)."""
    _interrupt_on_sigterm()
    exit_now(main())  # records are closed and processes reaped by now: skip the teardown


if __name__ == "__main__":  # python -m harness.cli: a normal exit, so profilers can report
    _interrupt_on_sigterm()
    sys.exit(main())
