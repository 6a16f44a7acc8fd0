"""The cheap rungs of the BCMD validation ladder, each a number beside its exact value, for the
tests and the validation report (Donev 2006, ch. 6; Donev et al. 2007, Sec. 4).

1. Disjoint cells: spheres whose cells never touch are independent billiards in shrinking balls,
   so Delta f = (d/2) ln(K/K_0) = d ln(dmu_max / dmu_min) exactly (Eq. 6.10 / 6.16), and the
   cell pressure is p_c = mu / Delta mu.
2. A point billiard in a random simplex intersected with a shrinking ball recovers the simplex
   volume (Eq. 6.13; :mod:`hardpack.freeenergy.billiard`).
3. The simplex-volume formula (Eq. 6.5) against qhull's volume of the vertex hull.
"""

from __future__ import annotations

import time

import numpy as np
import xarray as xr
from scipy.spatial import ConvexHull

from hardpack.freeenergy.bcmd import BCMDResult, run_bcmd
from hardpack.freeenergy.billiard import volume_estimate
from hardpack.freeenergy.simplex import log_simplex_volume
from hardpack.geometry.lattices import lattice_packing


def disjoint_cells(name="fcc", reps=(2, 2, 2), frozen="particle", seed=3) -> tuple[BCMDResult, float]:
    """BCMD of half-size lattice spheres from dmu = 0.5 to 0.05 (cells disjoint throughout) at
    constant rate gamma = 2e-3 (wall speed ~1e-3 of the thermal speed); returns the result and
    the exact Delta f = d ln 10.

    Parameters
    ----------
    name : str, optional
        Lattice name (:func:`hardpack.geometry.lattices.lattice_packing`).
    reps : tuple of int, optional
        Unit cells along each axis.
    frozen : str, optional
        What is frozen to fix the translations ("particle" or "cm").
    seed : int, optional
        Random seed.

    Returns
    -------
    result : BCMDResult
        The BCMD run.
    exact : float
        d ln 10.
    """
    p = lattice_packing(name, reps)
    p = p.replace(radii=p.radii * 0.5)
    res = run_bcmd(p, dmu_max=0.5, dmu_min=0.05, gamma0=2e-3, theta=0.0, frozen=frozen, seed=seed)
    return res, p.dim * np.log(10.0)


def random_simplex(n: int, rng) -> tuple[np.ndarray, np.ndarray, float]:
    """A random non-degenerate simplex around the origin: (A, b) with A x <= b (one facet per
    row, from qhull) and qhull's volume of its n + 1 vertices.

    Parameters
    ----------
    n : int
        Dimension.
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    a : numpy.ndarray of float, shape (n + 1, n)
        Facet normals.
    b : numpy.ndarray of float, shape (n + 1,)
        Facet offsets.
    volume : float
        qhull's volume.
    """
    while True:
        verts = rng.normal(size=(n + 1, n))
        verts -= verts.mean(axis=0)
        if abs(np.linalg.det(verts[1:] - verts[0])) > 0.1:
            break
    hull = ConvexHull(verts)
    eq = hull.equations  # normal . x + offset <= 0
    return eq[:, :-1], -eq[:, -1], hull.volume


def billiard_simplex(n=3, wall_ratio=1e-5, seed=5) -> tuple[float, float, int]:
    """BCMD volume of a random n-simplex (ball centred at the centroid, shrunk from containing
    the simplex to inscribed in it): (estimate, exact Eq. 6.5 volume, number of bounces).

    Parameters
    ----------
    n : int, optional
        Dimension.
    wall_ratio : float, optional
        As in :func:`hardpack.freeenergy.billiard.volume_estimate`.
    seed : int, optional
        Seed of the billiard.

    Returns
    -------
    estimate : float
        BCMD volume.
    exact : float
        Eq. 6.5 volume.
    bounces : int
        Wall bounces.
    """
    rng = np.random.default_rng(n)
    a, b, _ = random_simplex(n, rng)
    verts_dist = np.max(np.linalg.norm(_vertices(a, b), axis=1))
    est, bounces = volume_estimate(
        a, b, np.zeros(n), 1.01 * verts_dist, 0.99 * np.min(b / np.linalg.norm(a, axis=1)),
        wall_ratio=wall_ratio, seed=seed,
    )
    return est, float(np.exp(log_simplex_volume(a, b))), bounces


def _vertices(a, b):
    """Vertices of the simplex {a x <= b}: vertex k solves the n equations other than k."""
    idx = np.arange(a.shape[0])
    return np.array([np.linalg.solve(a[idx != k], b[idx != k]) for k in idx])


def simplex_formula_error(dims=(2, 3, 4, 5, 6), per_dim=3, seed=0) -> float:
    """Largest relative difference between Eq. 6.5 and qhull's volume over random simplices.

    Parameters
    ----------
    dims : sequence of int, optional
        Dimensions.
    per_dim : int, optional
        Simplices per dimension.
    seed : int, optional
        Random seed.

    Returns
    -------
    float
        The largest relative difference.
    """
    rng = np.random.default_rng(seed)
    worst = 0.0
    for n in dims:
        for _ in range(per_dim):
            a, b, vol = random_simplex(n, rng)
            worst = max(worst, abs(np.exp(log_simplex_volume(a, b)) / vol - 1.0))
    return worst


def _mean_error(values) -> tuple[float, float]:
    values = np.asarray(values, float)
    return float(values.mean()), float(values.std(ddof=1) / np.sqrt(values.size))


def ladder_dataset(seeds=tuple(range(3, 13))) -> xr.Dataset:
    """The rungs as one Dataset over ``check`` (the validation target ids ``bcmd-*``): each
    check's deviation from its exact value, our standard error of it, the number of samples it
    comes from, and the seconds it took.

    - disjoint cells: BCMD's Delta f minus d ln 10, over ``seeds``;
    - disjoint cells: p_c / (mu / dmu) - 1, over every segment of those runs;
    - point billiard: volume / exact - 1 of a random 3-simplex, over ``seeds``;
    - simplex formula: the worst |Eq. 6.5 / qhull - 1| (an identity: no error, one sample).

    Parameters
    ----------
    seeds : sequence of int, optional
        Seeds of the sampled checks.

    Returns
    -------
    xarray.Dataset
        Variables value, error, n_samples, seconds over ``check``.
    """
    t = time.perf_counter()
    runs = [disjoint_cells(seed=s) for s in seeds]
    exact = runs[0][1]
    df, df_err = _mean_error([res.delta_f - exact for res, _ in runs])
    ratios = np.concatenate([(res.to_dataset().p_c / ((1 + res.to_dataset().dmu_mid) / res.to_dataset().dmu_mid)).values
                             for res, _ in runs]) - 1.0
    pc, pc_err = _mean_error(ratios)
    t_cells = time.perf_counter() - t
    t = time.perf_counter()
    billiard, billiard_err = _mean_error([est / vol - 1.0 for est, vol, _ in
                                          (billiard_simplex(seed=s) for s in seeds)])
    t_billiard = time.perf_counter() - t
    t = time.perf_counter()
    formula = simplex_formula_error()
    t_formula = time.perf_counter() - t
    rows = [("bcmd-disjoint-cells-free-energy", df, df_err, len(seeds), t_cells),
            ("bcmd-disjoint-cells-pressure", pc, pc_err, ratios.size, 0.0),
            ("bcmd-billiard-simplex", billiard, billiard_err, len(seeds), t_billiard),
            ("bcmd-simplex-formula", formula, np.nan, 1, t_formula)]
    names, value, error, samples, seconds = zip(*rows)
    return xr.Dataset(
        {"value": ("check", np.array(value)), "error": ("check", np.array(error)),
         "n_samples": ("check", np.array(samples)), "seconds": ("check", np.array(seconds))},
        coords={"check": np.array(names, dtype=str)},
        attrs={"hardpack_kind": "bcmd_ladder"},
    )
