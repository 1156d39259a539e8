"""An option that cannot work, said with the caller's name for each option it names."""

from __future__ import annotations

from collections.abc import Mapping

from harness.errors import ConfigError

#: How a caller names each option key in a message ("--seed", "--hil-seed", "seed=").
Names = Mapping[str, str]


class _Default(dict[str, str]):
    """A key the caller has no name for is shown as the key itself."""

    def __missing__(self, key: str) -> str:
        return key


class OptionError(ConfigError):
    """`template` names options as ``{key}``; `render` fills in a caller's names.

    ``str(err)`` uses `names` given at construction (by default the plain
    keys), so a caller that does not render still shows one readable line.
    """

    def __init__(self, key: str, template: str, names: Names | None = None) -> None:
        self.key = key
        self.template = template
        super().__init__(self.render(names or {}))

    def render(self, names: Names, *, subject: bool = False) -> str:
        """The message with `names`; `subject`: a value's problem that does not say
        whose it is starts with the option's name ("threshold_param: ...")."""
        text = self.template.format_map(_Default(names))
        if subject and "{" + self.key + "}" not in self.template:
            return f"{_Default(names)[self.key]}: {text}"
        return text

    def named(self, names: Names) -> OptionError:
        """The same error worded with `names` (a caller's names for the keys)."""
        return OptionError(self.key, self.template, names)
