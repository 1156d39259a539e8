"""The results table as Parquet: typed columns, for pandas, Polars or DuckDB to read.

The CSV stays the durable record (one row appended per finished run); the
Parquet file is written from it, atomically, when a sweep ends. pyarrow is
an optional extra: ``pip install 'fossbot-hil[parquet]'``.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Mapping, Sequence
from pathlib import Path

from harness.atomic_write import write_atomically
from harness.errors import OptionError

WHOLE = {"seed", "ticks", "failed_ticks"}
TEXT = {"key", "scenario", "faults", "verdict", "first_failure", "worker"}  # others: numbers


def check_parquet_available() -> None:
    """Refuse --parquet before a campaign starts, naming the extra to install."""
    if importlib.util.find_spec("pyarrow") is None:
        raise OptionError("parquet", "{parquet} needs pyarrow: pip install 'fossbot-hil[parquet]'")


def _typed(column: str, text: str) -> object:
    if column in TEXT:
        return text
    if text == "":
        return None  # e.g. the threshold of a run that kept the scenario's own
    try:
        return int(text) if column in WHOLE else float(text)
    except ValueError:
        return None


def write_parquet(path: Path, rows: Sequence[Mapping[str, str]], columns: Sequence[str]) -> Path:
    """`rows` (as the CSV holds them) as a Parquet file with typed columns, atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    def kind(column: str) -> pa.DataType:
        return pa.string() if column in TEXT else pa.int64() if column in WHOLE else pa.float64()

    schema = pa.schema([(c, kind(c)) for c in columns])
    data = {c: [_typed(c, row.get(c, "")) for row in rows] for c in columns}
    table = pa.table(data, schema=schema)
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    return write_atomically(path, sink.getvalue().to_pybytes())
