"""Shared settings for the harness's own tests.

The ROS 2 tests run real nodes over real DDS. Where rclpy is missing they
must not pass silently by skipping: the run stops with the reason, unless
they were deselected on purpose (``pytest -m "not ros"``).
"""

from __future__ import annotations

import importlib.util
import json
import os
from collections.abc import Iterator
from pathlib import Path

import pytest


@pytest.fixture(autouse=True, scope="session")
def _own_cache_folder(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Every `fossbot-hil run` keeps its verdicts in the user's cache folder
    (docs/watch.md): the suite's runs keep theirs in a folder of the session's own,
    so they never reorder a user's own runs (nor the user's theirs)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("FOSSBOT_HIL_CACHE_DIR", str(tmp_path_factory.mktemp("fossbot-hil-cache")))
        yield


@pytest.hookimpl(optionalhook=True)  # pytest-xdist's hook
def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """`-n auto`: one worker more than cores. About a third of the suite's time is
    spent waiting (nodes starting, DDS discovery, deadlines, paced serial lines),
    not computing, so one more worker keeps the cores busy."""
    return len(os.sched_getaffinity(0)) + 1


@pytest.hookimpl(trylast=True)  # after -m has deselected what the user left out
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    wants_ros = [item for item in items if item.get_closest_marker("ros")]
    if wants_ros and importlib.util.find_spec("rclpy") is None:
        raise pytest.UsageError(
            f"{len(wants_ros)} selected tests need rclpy and Fast DDS, which are not installed: "
            "pip install '.[ros]' (or source ROS 2 Jazzy), or deselect them with -m 'not ros'"
        )
    items[:] = scheduled(items, _estimates(), _worksteal_workers(config))


# -- the order tests run in ----------------------------------------------------------

# Seconds each test file took (setup, call and teardown of all its tests) in a whole
# run of the suite: `pytest --store-durations` rewrites it. Only the order of the
# tests depends on it, never what they prove.
DURATIONS = Path(__file__).with_name("durations.json")
UNKNOWN_SLOW_S = 5.0  # a `slow` test of a file the table does not know yet
UNKNOWN_S = 0.3  # any other test of such a file
HEAVY_S = 5.0  # a file at least this long is dealt to a worker whole, longest first


def _estimates() -> dict[str, float]:
    try:
        return {str(k): float(v) for k, v in json.loads(DURATIONS.read_text()).items()}
    except (OSError, ValueError, AttributeError):
        return {}  # no table: every file is estimated from its marks


def _worksteal_workers(config: pytest.Config) -> int:
    """How many pytest-xdist workers share the tests by work stealing (1: no dealing)."""
    workers = int(getattr(config, "workerinput", {}).get("workercount", 1))
    return workers if config.getoption("dist", None) == "worksteal" else 1


def scheduled(
    items: list[pytest.Item], seconds: dict[str, float], workers: int
) -> list[pytest.Item]:
    """The order that ends the run soonest, its files kept whole (a module fixture runs
    once) and in collection order inside.

    pytest-xdist's worksteal gives each worker a contiguous share of the
    collection at the start (the first ``len // workers`` tests, then a share of
    the rest, ...); an idle worker then steals the *last* half of the longest
    queue. So each share starts with long files dealt longest first to the
    share with the least time (LPT), and ends with the short tests, which are
    what gets stolen: every long file starts early on some worker, and the run
    does not end with one worker on a long test while the others sit idle.
    Without work stealing the long files simply come first.
    """
    files: dict[str, list[pytest.Item]] = {}
    for item in items:
        files.setdefault(item.nodeid.split("::", 1)[0], []).append(item)

    def estimate(name: str) -> float:
        if name in seconds:
            return seconds[name]
        slow = sum(1 for item in files[name] if item.get_closest_marker("slow"))
        return slow * UNKNOWN_SLOW_S + (len(files[name]) - slow) * UNKNOWN_S

    longest_first = sorted(files, key=estimate, reverse=True)  # stable: ties as collected
    heavy = [name for name in longest_first if estimate(name) >= HEAVY_S]
    light = [item for name in files if name not in heavy for item in files[name]]
    if workers <= 1:
        return [item for name in heavy for item in files[name]] + light
    sizes: list[int] = []
    left = len(items)
    for done in range(workers):  # worksteal's first split, by count
        sizes.append(left // (workers - done))
        left -= sizes[-1]
    shares: list[list[pytest.Item]] = [[] for _ in sizes]
    loads = [0.0] * workers
    for name in heavy:
        room = [i for i in range(workers) if len(shares[i]) + len(files[name]) <= sizes[i]]
        least = min(room or range(workers), key=lambda i: loads[i])
        shares[least] += files[name]
        loads[least] += estimate(name)
    ordered: list[pytest.Item] = []
    for share, size in zip(shares, sizes, strict=True):  # the short tests fill each share
        take = max(0, size - len(share))
        ordered += share + light[:take]
        del light[:take]
    return ordered + light


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--store-durations",
        action="store_true",
        help=f"after the run, write the seconds each test file took into tests/{DURATIONS.name} "
        "(it orders later runs; files not run keep their entries)",
    )


_measured: dict[str, float] = {}


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    """Each phase's time, by file (with xdist: the controller sees every worker's)."""
    name = report.nodeid.split("::", 1)[0]
    _measured[name] = _measured.get(name, 0.0) + report.duration


def pytest_sessionfinish(session: pytest.Session) -> None:
    config = session.config
    if config.getoption("store_durations") and not hasattr(config, "workerinput"):
        # Merged into the table: a run of some files updates theirs, keeps the rest.
        table = {**_estimates(), **_measured}
        kept = {k: round(v, 1) for k, v in sorted(table.items()) if (config.rootpath / k).is_file()}
        DURATIONS.write_text(json.dumps(kept, indent=1) + "\n")
