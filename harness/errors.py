"""Errors the harness raises on purpose.

A ``ConfigError`` is the user's to fix (bad scenario file, unknown name,
missing executable, nonsense parameter): the CLI prints its one-line message
and exits 2. Anything else escaping is a harness bug.
"""

from __future__ import annotations


class HarnessError(Exception):
    """Base class of every error the harness raises deliberately."""


class ConfigError(HarnessError):
    """Bad input from the user; the message is one line naming what is wrong."""


class LinkError(HarnessError):
    """The link to the software under test broke in a way that ends the run."""
