"""Validation rows for the jamming densities of generated ensembles (LS engine and SLP MRJ runs).

An ensemble summary (``hardpack combine`` output with attributes ``ensemble`` and
``distribution``) is matched to a published system by its dimension and size distribution
(:func:`system_key`); the targets are those of ``targets.yaml``.
"""

from __future__ import annotations

import json

import numpy as np

from hardpack.validation.rows import Row, evaluate
from hardpack.validation.targets import Target, load_targets

#: (system, d) -> the LS jamming-density targets of that system
LS_TARGETS = {
    ("monodisperse", 3): ("donev-t11.1-phij-d3", "donev-t4.3-phi", "tj-t1-ls-phi-d3"),
    ("monodisperse", 4): ("donev-t11.1-phij-d4", "tj-t1-ls-phi-d4"),
    ("monodisperse", 5): ("donev-t11.1-phij-d5", "tj-t1-ls-phi-d5"),
    ("monodisperse", 6): ("donev-t11.1-phij-d6", "tj-t1-ls-phi-d6"),
    ("binary_1.4_equimolar", 2): ("donev-t4.2-phi",),
}


def system_key(summary) -> tuple | None:
    """('monodisperse' | 'binary_1.4_equimolar' | 'us_omega2', d) for recognised systems, else None.

    Parameters
    ----------
    summary : xarray.Dataset
        Ensemble summary (attribute distribution, variable d).

    Returns
    -------
    tuple of (str, int) or None
        The system and dimension.
    """
    spec = json.loads(summary.attrs.get("distribution", "{}"))
    d = int(np.asarray(summary["d"].values).ravel()[0]) if "d" in summary else None
    kind = spec.get("kind")
    if kind == "monodisperse":
        return ("monodisperse", d)
    if (kind == "bidisperse" and abs(spec.get("size_ratio", 0) - 1.4) < 1e-9
            and abs(spec.get("large_fraction", 0) - 0.5) < 1e-9):
        return ("binary_1.4_equimolar", d)
    if kind == "uniform_size" and abs(spec.get("omega", 0) - 2) < 1e-9:
        return ("us_omega2", d)
    return None


def n_particles(summary) -> int:
    """The number of particles of an ensemble summary (all its samples have the same N).

    Parameters
    ----------
    summary : xarray.Dataset
        Ensemble summary (variable N).

    Returns
    -------
    int
        N.
    """
    values = np.unique(np.asarray(summary["N"].values).ravel())
    return int(values.max())


def at_n(prefix: str, n: int) -> Target:
    """The row of a printed table keyed by N (targets ``<prefix>-n<N>``) at ``n``, or its nearest
    row: that one then reports n/a, since each printed row holds at its own N only.

    Parameters
    ----------
    prefix : str
        Target id prefix of the table.
    n : int
        System size.

    Returns
    -------
    Target
        The target.
    """
    rows = {int(tid.rsplit("-n", 1)[1]): t for tid, t in load_targets().items() if tid.startswith(prefix + "-n")}
    return rows[min(rows, key=lambda m: (abs(m - n), m))]


def _target(tid: str, n: int) -> Target:
    return at_n(tid, n) if tid in ("donev-t4.3-phi", "donev-t4.2-phi") else load_targets()[tid]


def _detail(s) -> str:
    parts = [f"N = {n_particles(s)}", f"{s.sizes['sample']} seeds"]
    if "growth_rate" in s:
        parts.append(f"Gamma = {float(np.asarray(s['growth_rate'].values).ravel()[0]):g}")
    if "Z" in s:
        parts.append(f"min reduced pressure {float(s['Z'].min()):.3g}")
    return ", ".join(parts)


def ls_rows(summaries) -> list[Row]:
    """Mean final phi of each recognised LS ensemble against Donev's Tables 11.1, 4.2 and 4.3.

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        LS ensemble summaries.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    out = []
    for s in summaries:
        key = system_key(s)
        n = n_particles(s)
        for tid in LS_TARGETS.get(key, ()):
            out.append(evaluate(_target(tid, n), samples=s["phi"].values, n=n, detail=_detail(s),
                                label=s.attrs.get("ensemble", "")))
    return out


def slp_mrj_rows(summaries) -> list[Row]:
    """Mean SLP density of each recognised ensemble against Torquato & Jiao's Table I (or the 2D
    polydisperse value of their Sec. V.A).

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        SLP ensemble summaries.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    out = []
    for s in summaries:
        key = system_key(s)
        if key is None:
            continue
        if key[0] == "monodisperse" and 3 <= key[1] <= 6:
            tid = f"tj-t1-slp-phi-d{key[1]}"
        elif key == ("us_omega2", 2):
            tid = "tj-sec5-poly2d-phi"
        else:
            continue
        n = n_particles(s)
        out.append(evaluate(load_targets()[tid], samples=s["phi"].values, n=n,
                            detail=f"N = {n}, {s.sizes['sample']} seeds", label=s.attrs.get("ensemble", "")))
    return out
