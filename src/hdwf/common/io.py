"""Atomic writers for the artefacts passed between stages.

Every artefact is written to a temporary name in its target directory and renamed into
place, so a crashed or killed job never leaves a half-written file that a later rule
would trust.
"""

from __future__ import annotations

import errno
import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Mapping

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from hdwf.common.errors import InputError
from hdwf.common.jsonsafe import json_safe

if TYPE_CHECKING:   # pandas is imported where a table is read: a solve job writes Arrow and never needs it
    import pandas as pd

PROVENANCE_KEY = b"hdwf.provenance"
EXTRA_KEY = b"hdwf.meta"


@contextmanager
def atomic_path(path: str | Path, *, replace: bool = True):
    """Yield a temporary path beside ``path``; move it to ``path`` only if the block succeeds.

    With ``replace=False`` an existing ``path`` is never replaced, even one made while the block ran
    (a hard link fails where a rename would not): ``FileExistsError``, and the temporary file is gone.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        # mkstemp makes the file private (0600); give it the permissions a plain open() would.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        if replace:
            os.replace(tmp, path)
        else:
            _move_unless_exists(Path(tmp), path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _move_unless_exists(tmp: Path, path: Path) -> None:
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise
    except OSError:   # no hard links on this file system: check, then rename (a narrow race remains)
        if path.exists():
            raise FileExistsError(errno.EEXIST, "File exists", str(path)) from None
        os.replace(tmp, path)
        return
    tmp.unlink()


def unit_of(column: str) -> str | None:
    """The unit encoded in a column name: ``twist_arcmin`` -> ``arcmin``."""
    for suffix in ("_arcmin", "_mm", "_Nm", "_um", "_s", "_MB"):
        if column.endswith(suffix):
            return suffix[1:]
    return None


def arrow_table(columns: Mapping[str, object]) -> pa.Table:
    """An Arrow table from ``{column: sequence}``, NaN stored as null as ``pandas`` stores it."""
    return pa.table({name: _arrow_column(values) for name, values in columns.items()})


def _arrow_column(values) -> pa.Array:
    typed = pa.array(values)    # typed before NaN becomes null: a failed row's NaN stays a double
    return pa.array(values, type=typed.type, from_pandas=True) if pa.types.is_floating(typed.type) else typed


def arrow_row(row: Mapping[str, object]) -> pa.Table:
    """A one-row Arrow table from ``{column: value}`` (``arrow_table``)."""
    return arrow_table({name: [value] for name, value in row.items()})


def write_parquet(df: pd.DataFrame | pa.Table, path: str | Path, *, provenance: dict | None = None,
                  meta: dict | None = None, schema: pa.Schema | None = None) -> Path:
    """Write ``df`` (a DataFrame or an Arrow table) atomically; units from column names go into the
    Arrow field metadata."""
    if isinstance(df, pa.Table):
        table = df if schema is None else df.cast(schema)
    else:
        table = pa.Table.from_pandas(df, schema=schema, preserve_index=False)
    fields = []
    for field in table.schema:
        unit = unit_of(field.name)
        fmeta = dict(field.metadata or {})
        if unit:
            fmeta[b"unit"] = unit.encode()
        fields.append(field.with_metadata(fmeta) if fmeta else field)
    file_meta = dict(table.schema.metadata or {})
    file_meta.pop(b"pandas", None)  # pandas' own index metadata is noise for other readers
    if provenance is not None:
        file_meta[PROVENANCE_KEY] = json.dumps(provenance, sort_keys=True).encode()
    if meta is not None:
        file_meta[EXTRA_KEY] = json.dumps(meta, sort_keys=True).encode()
    table = table.cast(pa.schema(fields, metadata=file_meta))
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return Path(path)


def read_parquet_meta(path: str | Path) -> tuple[dict | None, dict | None]:
    """The (provenance, extra metadata) stored in a Parquet file written by ``write_parquet``."""
    meta = pq.read_schema(path).metadata or {}
    prov = json.loads(meta[PROVENANCE_KEY]) if PROVENANCE_KEY in meta else None
    extra = json.loads(meta[EXTRA_KEY]) if EXTRA_KEY in meta else None
    return prov, extra


def write_json(obj, path: str | Path) -> Path:
    """Write ``obj`` atomically as strict JSON: NaN and inf as null (``jsonsafe``), which every JSON
    reader takes, where Python's ``NaN`` / ``Infinity`` are not JSON."""
    text = json.dumps(json_safe(obj), indent=2, sort_keys=False, allow_nan=False) + "\n"
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def read_json(path: str | Path):
    return json.loads(Path(path).read_text())


def read_table(path: str | Path, required: dict[str, str]) -> pd.DataFrame:
    """Read a CSV or Parquet table (by extension) and check its columns and values.

    ``required`` maps column name -> kind: ``"float"`` (finite number), ``"int"``, ``"str"``.
    Raises InputError naming the file, the 1-based data row and the column of the first
    bad value; a missing column is named with the columns that were found.
    """
    import pandas as pd

    path = Path(path)
    if not path.exists():
        raise InputError(path, "file not found")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        # Read as text first so a non-numeric cell is reported as written, not as NaN.
        df = pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    elif suffix in (".parquet", ".pq"):
        df = pd.read_parquet(path)
    else:
        raise InputError(path, f"unknown file type '{suffix}': use .csv or .parquet")
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise InputError(path, f"missing column(s) {missing}; found {list(df.columns)}", field=missing[0])
    if len(df) == 0:
        raise InputError(path, "the table has no data rows")
    out = pd.DataFrame(index=df.index)
    for col, kind in required.items():
        raw = df[col]
        if kind == "str":
            values = raw.astype(str).str.strip()
            bad = values == ""
            if bad.any():
                i = int(np.argmax(bad.to_numpy()))
                raise InputError(path, "empty value", row=i + 1, field=col, value=raw.iloc[i])
            out[col] = values
            continue
        values = pd.to_numeric(raw, errors="coerce")
        bad = ~np.isfinite(values.to_numpy(dtype=float))
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(path, "not a finite number", row=i + 1, field=col, value=raw.iloc[i])
        if kind == "int":
            if not np.all(values == np.round(values)):
                i = int(np.argmax(values != np.round(values)))
                raise InputError(path, "not an integer", row=i + 1, field=col, value=raw.iloc[i])
            values = values.astype("int64")
        out[col] = values
    extra = [c for c in df.columns if c not in required]
    for col in extra:
        out[col] = df[col]
    return out.reset_index(drop=True)
