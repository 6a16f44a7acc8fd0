"""Validation rows: a reproduced value judged against a target, the gate, and the report formats.

A :class:`Row` is one measurement of one :class:`~hardpack.validation.targets.Target`. Its status:

- ``pass``: |reproduced - published| <= tolerance + 2 u (u: our standard error over seeds, or our
  spread over samples sd sqrt(1 + 1/n) when the published value is one sample);
- ``fail``: it does not, or the value is missing (NaN) for any seed;
- ``n/a``: the system is too small (or too large), or has too few seeds or sizes, for the
  tolerance to mean something (the target's ``min_n``, ``max_n``, ``min_seeds``, ``min_sizes``);
- ``known deviation``: it fails, and the target states why (a documented deviation);
- ``deviation passes``: a documented deviation that now passes; the table must be updated.

The gate (:func:`gate`) fails on ``fail`` and ``deviation passes`` rows, and when fewer than a
minimum number of reproduction and analytic rows are applicable, so that n/a cannot empty it.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, fields

import numpy as np
import xarray as xr

from hardpack.validation.targets import KINDS, Target

PASS, FAIL, NA, KNOWN, DEVIATION_PASSES = "pass", "fail", "n/a", "known deviation", "deviation passes"
STATUSES = (PASS, FAIL, KNOWN, DEVIATION_PASSES, NA)
APPLICABLE = (PASS, FAIL, KNOWN, DEVIATION_PASSES)


@dataclass(frozen=True)
class Row:
    """One reproduced value beside its target (:func:`evaluate`).

    Attributes
    ----------
    target, study, kind, quantity, citation : str
        The target's id, study, kind, quantity and citation (:class:`Target`).
    published : float
        The published value (the target's, or the fit it names evaluated for this row).
    reproduced, uncertainty : float
        The reproduced value and our uncertainty of it (NaN: none).
    tolerance : float
        The absolute tolerance.
    tolerance_origin, tolerance_note : str
        Where the tolerance comes from and why (the target's).
    status : str
        pass, fail, n/a, known deviation or deviation passes (module docstring).
    detail : str
        Notes: why the row is n/a or has no value, what was measured, the known deviation.
    label : str
        Which ensemble or parameter the row is for.
    """

    target: str
    study: str
    kind: str
    quantity: str
    citation: str
    published: float
    reproduced: float
    uncertainty: float
    tolerance: float
    tolerance_origin: str
    tolerance_note: str
    status: str
    detail: str = ""
    label: str = ""

    @property
    def passed(self) -> bool:
        return self.status == PASS

    @property
    def applicable(self) -> bool:
        return self.status in APPLICABLE


def seed_statistics(values, single_sample: bool = False) -> tuple[float, float, int, int]:
    """Mean and uncertainty of per-seed values, with the counts of seeds and of missing ones.

    The uncertainty is the standard error s / sqrt(n), or for ``single_sample`` targets the
    prediction spread s sqrt(1 + 1/n) of one more sample; NaN with one seed. Missing (NaN) values
    are counted, not dropped: the caller fails the row if any.

    Parameters
    ----------
    values : iterable of float
        Per-seed values (NaN: missing).
    single_sample : bool, optional
        Return the prediction spread instead of the standard error.

    Returns
    -------
    mean : float
        Mean of the finite values (NaN if none).
    uncertainty : float
        As above.
    n_seeds : int
        Number of values.
    n_missing : int
        Number of NaN values.
    """
    values = np.asarray(list(values), float).ravel()
    finite = values[np.isfinite(values)]
    n_missing = int(values.size - finite.size)
    if finite.size == 0:
        return math.nan, math.nan, int(values.size), n_missing
    mean = float(finite.mean())
    if finite.size < 2:
        return mean, math.nan, int(values.size), n_missing
    sd = float(finite.std(ddof=1))
    unc = sd * math.sqrt(1 + 1 / finite.size) if single_sample else sd / math.sqrt(finite.size)
    return mean, unc, int(values.size), n_missing


def evaluate(target: Target, reproduced: float = math.nan, uncertainty: float = math.nan, *,
             samples=None, n: int | None = None, seeds: int | None = None, sizes: int | None = None,
             published: float | None = None, detail: str = "", label: str = "") -> Row:
    """Judge a reproduced value against ``target``.

    Parameters
    ----------
    target : Target
        What is compared and how.
    reproduced, uncertainty : float
        The reproduced value and our uncertainty of it (NaN: none). Ignored with ``samples``.
    samples : array_like, optional
        Per-seed values: the row uses their mean and :func:`seed_statistics` (a missing value
        fails the row, with the count in the detail).
    n, seeds, sizes : int, optional
        Particles per system, number of seeds, number of distinct system sizes of the
        measurement, for the target's applicability limits.
    published : float, optional
        The published value when the target computes it (``published_from``: a fit evaluated at
        the row's parameter).
    detail, label : str
        What was measured (protocol, N, seeds), and which ensemble or parameter the row is for.

    Returns
    -------
    Row
        The target's identity and citation, the published value, the reproduced value and its
        uncertainty, the absolute tolerance with its origin, and the status: pass / fail within
        tolerance + 2 uncertainties, n/a when the measurement is outside the target's
        applicability limits, known deviation (or "deviation passes") for targets with a
        documented deviation.
    """
    missing = 0
    if samples is not None:
        reproduced, uncertainty, seeds, missing = seed_statistics(samples, target.single_sample)
    value = target.published if published is None else float(published)
    tolerance = target.absolute_tolerance(value)
    reason = target.not_applicable(n, seeds, sizes)
    notes = [detail] if detail else []
    if reason:
        status = NA
        notes.insert(0, f"n/a: {reason}")
    elif missing or not math.isfinite(reproduced):
        status = FAIL
        notes.insert(0, f"{missing} of {seeds} seeds gave no value" if missing else "no value")
    else:
        slack = tolerance + (2 * uncertainty if math.isfinite(uncertainty) else 0.0)
        # relative round-off allowance, so that a value equal to the print is not lost to binary
        ok = abs(reproduced - value) <= slack * (1 + 1e-9) + 1e-15 * abs(value)
        status = PASS if ok else FAIL
    if target.known_deviation and status in (PASS, FAIL):
        status = DEVIATION_PASSES if status == PASS else KNOWN
        notes.append(f"known deviation: {target.known_deviation}")
    return Row(target.id, target.study, target.kind, target.quantity, target.citation, value,
               float(reproduced), float(uncertainty), tolerance, target.tolerance_origin,
               target.tolerance_note, status, "; ".join(notes), label)


def counts(rows: list[Row]) -> dict[str, Counter]:
    """Status counts per kind of row.

    Parameters
    ----------
    rows : list of Row
        The rows.

    Returns
    -------
    dict of str to collections.Counter
        Kind -> status -> count.
    """
    out = {kind: Counter() for kind in KINDS}
    for r in rows:
        out[r.kind][r.status] += 1
    return out


def gate(rows: list[Row], min_applicable: int = 0) -> list[str]:
    """Reasons the gate fails (empty when it passes): failing rows, documented deviations that now
    pass, and fewer than ``min_applicable`` applicable reproduction and analytic rows.

    Parameters
    ----------
    rows : list of Row
        The evaluated rows.
    min_applicable : int, default 0
        Fewest applicable rows of kind "reproduction" or "analytic" the gate accepts.

    Returns
    -------
    list of str
        One line per problem; empty when the gate passes.
    """
    problems = [f"{r.target}{f' [{r.label}]' if r.label else ''}: {r.status}: {r.quantity} "
                f"(published {_fmt(r.published)}, reproduced {_fmt(r.reproduced)})"
                for r in rows if r.status in (FAIL, DEVIATION_PASSES)]
    applicable = sum(r.applicable for r in rows if r.kind in ("reproduction", "analytic"))
    if applicable < min_applicable:
        problems.append(f"only {applicable} reproduction and analytic rows are applicable; the gate "
                        f"needs at least {min_applicable}")
    return problems


def to_dataset(rows: list[Row]) -> xr.Dataset:
    """Rows as a Dataset over dimension ``row`` (strings, floats; the headline counts in attrs).

    Parameters
    ----------
    rows : list of Row
        The evaluated rows.

    Returns
    -------
    xarray.Dataset
        One variable per field of :class:`Row` along ``row`` (float fields as floats, the others
        as strings); attributes ``hardpack_kind`` = "validation", ``n_rows`` and
        ``n_<kind>_<status>`` counts. :func:`from_dataset` reads it back.
    """
    data = {}
    for f in fields(Row):
        values = [getattr(r, f.name) for r in rows]
        if f.type == "float":
            data[f.name] = ("row", np.asarray(values, float))
        else:
            data[f.name] = ("row", np.asarray(values, dtype=str))
    ds = xr.Dataset(data)
    ds.attrs.update(hardpack_kind="validation", n_rows=len(rows))
    for kind, c in counts(rows).items():
        for status in STATUSES:
            ds.attrs[f"n_{kind}_{status}".replace(" ", "_").replace("/", "")] = int(c[status])
    return ds


def from_dataset(ds: xr.Dataset) -> list[Row]:
    """The rows of a validation Dataset written by :func:`to_dataset`.

    Parameters
    ----------
    ds : xarray.Dataset
        The validation dataset (dimension ``row``).

    Returns
    -------
    list of Row
        The rows.
    """
    out = []
    for i in range(ds.sizes["row"]):
        kw = {}
        for f in fields(Row):
            value = ds[f.name].values[i]
            kw[f.name] = float(value) if f.type == "float" else str(value)
        out.append(Row(**kw))
    return out


def _fmt(x: float) -> str:
    if not math.isfinite(x):
        return "-"
    return f"{x:.6g}"


_MARK = {PASS: "pass", FAIL: "**FAIL**", NA: "n/a", KNOWN: "known deviation", DEVIATION_PASSES: "**deviation passes**"}


def headline(rows: list[Row]) -> list[str]:
    """One line per kind: pass / fail / known deviation / deviation passes / n/a counts.

    Parameters
    ----------
    rows : list of Row
        The rows.

    Returns
    -------
    list of str
        Markdown list items.
    """
    lines = []
    for kind, c in counts(rows).items():
        applicable = sum(c[s] for s in APPLICABLE)
        lines.append(f"- **{kind}**: {c[PASS]} of {applicable} applicable rows pass; {c[FAIL]} fail, "
                     f"{c[KNOWN]} known deviations, {c[DEVIATION_PASSES]} known deviations that now "
                     f"pass; {c[NA]} n/a (system too small or too few seeds)")
    return lines


def to_markdown(rows: list[Row], problems: list[str], unmeasured: list[Target] = (),
                title: str = "hardpack validation report") -> str:
    """A readable report: the gate's verdict, the counts per kind, then one table per study.

    Parameters
    ----------
    rows : list of Row
        The evaluated rows.
    problems : list of str
        The gate's problems (:func:`gate`); empty for a passed gate.
    unmeasured : sequence of Target, default ()
        Targets this configuration does not measure, listed at the end.
    title : str, default "hardpack validation report"
        The top heading.

    Returns
    -------
    str
        The report in Markdown.
    """
    verdict = ("**Gate: passed.**" if not problems else
               "**Gate: FAILED.**\n\n" + "\n".join(f"- {p}" for p in problems))
    lines = [f"# {title}", "", verdict, "", *headline(rows), "",
             "Each row puts a published number beside the reproduced one. The tolerance comes from "
             "the source (printed digits, stated error, its spread over samples) or is zero and the "
             "row relies on our own standard error; a row passes when the difference is within the "
             "tolerance plus two of our standard errors (for a published single packing, two of our "
             "spreads over packings). Targets, tolerances and their origins: "
             "`src/hardpack/validation/targets.yaml`.", ""]
    for study in dict.fromkeys(r.study for r in rows):
        lines += [f"## {study}", "",
                  "| target | quantity | published | reproduced | +- | tolerance | status | detail | source |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in rows:
            if r.study != study:
                continue
            label = f" [{r.label}]" if r.label else ""
            lines.append(
                f"| `{r.target}`{label} | {r.quantity} | {_fmt(r.published)} | {_fmt(r.reproduced)} | "
                f"{_fmt(r.uncertainty)} | {_fmt(r.tolerance)} ({r.tolerance_origin}: {r.tolerance_note}) | "
                f"{_MARK[r.status]} | {r.detail} | {r.citation} |")
        lines.append("")
    if unmeasured:
        lines += ["## Targets this configuration does not measure", "",
                  ", ".join(f"`{t.id}`" for t in unmeasured), ""]
    return "\n".join(lines)
