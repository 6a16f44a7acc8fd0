"""Validation rows: a published number beside the reproduced one, and the report formats.

Each :class:`Row` names its source (file and line or table), the published value as printed, the
reproduced value with its uncertainty over seeds (NaN when the value is deterministic), the
tolerance and why it is that, and whether the row passes. A failing row is information: it stays
in the report.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
import xarray as xr


@dataclass(frozen=True)
class Row:
    study: str
    quantity: str
    source: str
    published: float
    reproduced: float
    uncertainty: float
    tolerance: float
    why: str
    passed: bool
    detail: str = ""


def mean_sem(values) -> tuple[float, float]:
    """Mean and standard error (sample std / sqrt(n)) of the finite values: (NaN, NaN) when there
    are none, NaN error for a single value (one seed has no spread to quote)."""
    values = np.asarray(list(values), float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return math.nan, math.nan
    sem = values.std(ddof=1) / math.sqrt(values.size) if values.size > 1 else math.nan
    return float(values.mean()), float(sem)


def within(reproduced: float, published: float, tolerance: float, uncertainty: float = math.nan) -> bool:
    """|reproduced - published| <= tolerance (+ 2 sigma of the reproduced value when it has one)."""
    slack = tolerance + (2 * uncertainty if math.isfinite(uncertainty) else 0.0)
    return bool(math.isfinite(reproduced) and abs(reproduced - published) <= slack)


def to_dataset(rows: list[Row]) -> xr.Dataset:
    """Rows as a Dataset over dimension ``row``."""
    data = {}
    for f in fields(Row):
        values = [getattr(r, f.name) for r in rows]
        if f.type in ("float",):
            data[f.name] = ("row", np.asarray(values, float))
        elif f.type == "bool":
            data[f.name] = ("row", np.asarray(values, np.int8))
        else:
            data[f.name] = ("row", np.asarray(values, dtype=str))
    ds = xr.Dataset(data)
    ds.attrs.update(hardpack_kind="validation", n_rows=len(rows), n_passed=int(sum(r.passed for r in rows)))
    return ds


def _fmt(x: float) -> str:
    if not math.isfinite(x):
        return "-"
    return f"{x:.6g}"


def to_markdown(rows: list[Row], title: str = "hardpack validation report") -> str:
    """A readable report: the pass rate, then one table per study."""
    n_pass = sum(r.passed for r in rows)
    lines = [f"# {title}", "",
             f"{n_pass} of {len(rows)} rows pass ({100 * n_pass / max(len(rows), 1):.0f}%). "
             "Each row puts a published number beside the reproduced one; the uncertainty is the "
             "standard error over seeds where there are several; a row passes when the difference is "
             "within the tolerance plus two standard errors.", ""]
    for study in dict.fromkeys(r.study for r in rows):
        lines += [f"## {study}", "",
                  "| quantity | source | published | reproduced | +- | tolerance | why | pass | detail |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in rows:
            if r.study != study:
                continue
            lines.append(
                f"| {r.quantity} | {r.source} | {_fmt(r.published)} | {_fmt(r.reproduced)} | "
                f"{_fmt(r.uncertainty)} | {_fmt(r.tolerance)} | {r.why} | {'yes' if r.passed else '**no**'} | {r.detail} |"
            )
        lines.append("")
    return "\n".join(lines)
