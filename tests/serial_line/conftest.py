"""The serial line's messages name the port option as the CLI does (--port)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from harness.option_names import speaking


@pytest.fixture(autouse=True)
def _cli_names() -> Iterator[None]:
    with speaking({"port": "--port"}):
        yield
