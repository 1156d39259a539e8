"""A worker plugin: a task's messages name options as the client's caller does (the
CLI's flags, ``harness.option_names``), not as bare keys. Imports distributed."""

from __future__ import annotations

from distributed import WorkerPlugin

from harness.option_names import speak


class OptionNames(WorkerPlugin):
    name = "fossbot-hil-option-names"

    def __init__(self, names: dict[str, str]) -> None:
        self.names = names

    def setup(self, worker: object) -> None:
        speak(self.names)
