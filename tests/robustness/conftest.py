"""The robustness properties draw the same examples whatever else ran in the session.

Hypothesis (6.131 on) mixes into its draws the literals of every local module
already imported. This project is installed in place, so the harness's modules
count as local, and which of them earlier tests happened to import changed the
derandomized examples: the samples' counts (how many ran, how many were
refused) moved with the order of the tests, and a run of this folder after the
grading tests drew a scenario whose keys were all deleted. Here the pool of
local literals is empty, so the examples depend on the seed alone.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest


@pytest.fixture(autouse=True)
def examples_from_the_seed_alone(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """No local literals in Hypothesis's draws during each test (a no-op on versions without)."""
    try:
        from hypothesis.internal.conjecture import providers
        from hypothesis.internal.constants_ast import Constants
    except ImportError:  # an older or newer Hypothesis: it has no such pool, or moved it
        yield
        return
    if not hasattr(providers, "_get_local_constants"):
        yield
        return
    monkeypatch.setattr(providers, "_get_local_constants", Constants)
    providers.CONSTANTS_CACHE.cache.clear()  # pools computed with earlier tests' literals
    yield
    providers.CONSTANTS_CACHE.cache.clear()  # and ours, empty, for the tests after
