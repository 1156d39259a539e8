"""A Dask client opened in the background, while the command does its own first work.

An embedded cluster takes seconds to start (a scheduler, a fork server, the workers'
imports); ``grade`` has seconds of its own before it needs one (finding and checking
the class, the sandbox probe, simulating each scenario once for its tick count). So
the cluster starts first, in a thread, and the command asks for the client when it
has a task to give. Whatever ``open_client`` raises (a ConfigError: a scheduler that
does not answer) is raised by `client()`; the cluster is closed with the context,
by the thread that opened it, so nothing is left running.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator
from typing import Any

from harness.errors import HarnessError

__all__ = ["START_WAIT_S", "ClientSoon", "client_soon"]

# For the cluster to start: Dask's own waits (a scheduler's connect, a worker's start,
# --worker-wait) are shorter; this only bounds a start that hangs past them all.
START_WAIT_S = 300.0
CLOSE_WAIT_S = 60.0  # for its workers and scheduler to stop


class ClientSoon:
    """`open_client(**how)` entered in a thread; `client()` waits for it (bounded).

    The thread opens the client and closes it too (a Client's context belongs to the
    thread that entered it), when `close()` asks."""

    def __init__(self, **how: Any) -> None:
        self._how = how
        self._client: Any = None
        self._error: BaseException | None = None
        self._opened = threading.Event()  # the client is up, or its start failed
        self._closing = threading.Event()
        self._thread = threading.Thread(target=self._hold, name="fossbot-hil-cluster")
        self._thread.daemon = True  # never keeps a failing command alive (close() waits)

    def _hold(self) -> None:
        from harness.cluster.client import open_client

        try:
            with open_client(**self._how) as client:
                self._client = client
                self._opened.set()
                self._closing.wait()
        except BaseException as err:  # noqa: BLE001 - handed to the thread asking
            self._error = self._error or err
        finally:
            self._opened.set()

    def start(self) -> ClientSoon:
        self._thread.start()
        return self

    def client(self, timeout: float = START_WAIT_S) -> Any:
        """The client, once its cluster is up; what the start raised, raised here."""
        if not self._opened.wait(timeout):
            raise HarnessError(f"the Dask cluster did not start within {timeout:g} s")
        if self._error is not None:
            raise self._error
        if self._client is None:
            raise HarnessError("the Dask cluster closed before it was used")
        return self._client

    def close(self) -> None:
        """Close the cluster, once its start has ended (each wait bounded)."""
        self._closing.set()
        self._thread.join(START_WAIT_S + CLOSE_WAIT_S)


@contextlib.contextmanager
def client_soon(**how: Any) -> Iterator[ClientSoon]:
    """`open_client(**how)` started now in the background, closed when the context ends."""
    soon = ClientSoon(**how).start()
    try:
        yield soon
    finally:
        soon.close()
