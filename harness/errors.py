"""Errors the harness raises on purpose.

A ``ConfigError`` is the user's to fix (bad scenario file, unknown name,
missing executable, nonsense parameter): the CLI prints its one-line message
and exits 2. Anything else escaping is a harness bug.
"""

from __future__ import annotations

import signal

from harness.option_names import Names, escaped, worded


def one_line(err: BaseException, limit: int = 200) -> str:
    """Another library's error as one short line for a message (its type when it says
    nothing)."""
    return " ".join(str(err).split())[:limit] or type(err).__name__


class HarnessError(Exception):
    """Base class of every error the harness raises deliberately."""


class ConfigError(HarnessError):
    """Bad input from the user; the message is one line naming what is wrong."""


class OptionError(ConfigError):
    """A bad option value or combination; `template` names options as ``{key}``.

    ``str(err)`` words the keys as `names` do, by default as this process's
    caller names them (`harness.option_names.speak`); `render` words them
    for another caller.
    """

    def __init__(self, key: str, template: str, names: Names | None = None) -> None:
        self.key, self.template = key, template
        super().__init__(self.render(names))

    @classmethod
    def saying(cls, key: str, text: str) -> OptionError:
        """`text` (values and all, braces kept) as option `key`'s problem: "{key} text"."""
        return cls(key, f"{{{key}}} " + escaped(text))

    def render(self, names: Names | None = None, *, subject: bool = False) -> str:
        """The message with `names`; `subject`: a value's problem that does not say
        whose it is starts with the option's name ("threshold_param: ...")."""
        text = worded(self.template, names)
        if subject and "{" + self.key + "}" not in self.template:
            return f"{worded('{' + self.key + '}', names)}: {text}"
        return text

    def named(self, names: Names) -> OptionError:
        """The same error worded with `names` (a caller's names for the keys)."""
        return OptionError(self.key, self.template, names)


class LinkError(HarnessError):
    """The link to the software under test broke in a way that ends the run."""


class NeverReady(LinkError):
    """The node runs, but never used the topics the harness waited on: this scenario's
    failure to come up, not the node's (a later scenario with other topics may run)."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C or SIGTERM: the run stops, and says what it had judged.

    `signum` is the signal (the exit code is 128 + signum); `results` holds
    what was judged up to then, the interrupted scenario last, once the
    runner has gathered it; `summary` is what the command tells the user.
    """

    def __init__(self, signum: int, results: list | None = None, summary: str = "") -> None:
        super().__init__(signum)
        self.signum = signum
        self.results = results if results is not None else []
        self.summary = summary

    @classmethod
    def of(cls, err: KeyboardInterrupt) -> Interrupted:
        """`err` as an Interrupted: a plain KeyboardInterrupt is Python's Ctrl-C (SIGINT)."""
        return err if isinstance(err, Interrupted) else cls(signal.SIGINT)

    @property
    def name(self) -> str:
        """The signal's name, e.g. SIGTERM."""
        return signal.Signals(self.signum).name

    @property
    def exit_code(self) -> int:
        """128 + the signal's number, as shells report a command a signal ended."""
        return 128 + self.signum
