"""A Dask worker's messages name options as its client's caller does (the CLI's flags):
sweep, hunt, audit and grade judge on workers, and a problem found there must read as
`fossbot-hil` names the option, not as a bare key."""

from __future__ import annotations

import pytest

from harness.cluster.client import open_client
from harness.option_names import named, speaking

pytestmark = pytest.mark.timeout(120)


def test_a_worker_speaks_its_clients_names() -> None:
    with speaking({"port": "--port"}), open_client(workers=1) as client:
        assert client.submit(named, "port", pure=False).result(timeout=60) == "--port"
