"""Bounding-cell MD for a nearly jammed ellipse packing, linearised about the jamming point.

Donev 2006, dissertation secs. 6.3 and 6.4.3; Donev, Stillinger & Torquato 2007, Secs. 3-4.4 and
Appendix C. The packing is shrunk by (1 - delta) about its centroids; each ellipse lives in a
bounding cell of its own shape, scaled by mu = 1 + Delta mu about its initial centroid at its
initial orientation (Donev 2006, sec. 6.3.1); the cells shrink at d(Delta mu)/dt = -gamma,
gamma = gamma_0 (Delta mu / Delta mu_max)^theta, updated each time Delta mu has fallen by
``segment_fraction`` (sec. 6.3.4), from Delta mu_max to the disjoint-cell point, and
Delta f = (N_f / 2) ln(K / K_0) / N_eff (Eq. 6.12, per free-centroid particle).

Which dynamics. Donev et al. integrated the nonlinear motion and had to predict collisions of an
ellipse with the ellipse enclosing it, which they found numerically unstable (a missed collision
lets a particle leave its cell for good), and which limited their accuracy (3.61 +- 0.01 against
the exact 3.6693). Here the whole problem is linearised about the jammed configuration, exactly as
the exact reference is: the contacts are the planes -a_c . dQ <= h_c of the jamming polytope
(:func:`hardpack.freeenergy.ellipses.linear_model`) and each cell is the convex body of Eq. C1.
Particles move on straight lines in (dr, dphi) between events, pair collisions are instantaneous
reflections in the kinetic metric (mass 1, moment of inertia (a^2 + b^2)/4), and cell collisions
are bounces off the moving convex wall, whose time is the first root of a convex function
(:mod:`hardpack.freeenergy._ellipse_kernel`). Both sides therefore compute the delta -> 0 limit
of the same volume: the difference is the BCMD error alone (finite gamma, finite sampling, and
the part of the simplex that the cells at Delta mu_max cut off, reported as
``vertices_outside``). Non-contact pairs are ignored, which is valid while Delta mu_max is well
below their gap (``next_gap``).

The simplex of a disordered packing is very elongated (Donev 2006, sec. 6.4.2: Delta mu_max /
delta ~ 10^3 for spheres), and BCMD measures ln(|P cap cells(Delta mu_max)| / V_min), not
ln(|P| / V_min), when the initial cells cut it: ``inside_fraction`` (uniform points of P inside
the cells at Delta mu_max) gives ``exact_in_cells`` = exact + ln(inside_fraction) / N_eff, the
exact value of the quantity this run measures, so that the method's own error and the cut are
told apart.

Lengths are in units of the smallest semiaxis (Donev 2006, sec. 6.2.1), time in units with m = 1
and kT = 1 at the start, so gamma is the shrink rate of Donev's tables.
"""

from __future__ import annotations

import time

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.freeenergy import _ellipse_kernel as kern
from hardpack.freeenergy.bcmd import _check, _check_schedule, shrink_schedule
from hardpack.freeenergy.ellipses import (
    _check_round_rotations,
    _free_masks,
    ellipse_simplex_reference,
    linear_model,
)
from hardpack.geometry.packing import Packing
from hardpack.jamming.ellipsoids import check_ellipsoid_packing


def _vertices(at: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The N_f + 1 vertices of the simplex {x : at x <= h} (vertex k: all facets but k tight)."""
    m = at.shape[0]
    out = np.empty((m, at.shape[1]))
    for k in range(m):
        keep = np.arange(m) != k
        out[k] = np.linalg.solve(at[keep], h[keep])
    return out


def _outside_cells(qv: np.ndarray, cell: np.ndarray, dmu: float, movers: np.ndarray) -> bool:
    """Whether the configuration qv (N, 3) leaves some particle's cell of size dmu."""
    zeros_qd, tq0 = np.zeros_like(qv), np.zeros(len(qv))
    return any(kern.cell_value(i, 0.0, qv, zeros_qd, tq0, cell, dmu, 0.0, 0.0) > 0 for i in movers)


def ellipse_bcmd(
    packing: Packing,
    *,
    delta: float = 1e-4,
    contact_tol: float = 1e-6,
    fixed_translation=(0,),
    fixed_rotation=(),
    dmu_max: float = 1.5e-2,
    gamma0: float = 1e-3,
    theta: float = 0.5,
    seed: int = 0,
    equilibration: float = 50.0,
    segment_fraction: float = 0.01,
    max_events: int = 10**10,
    n_inside_samples: int = 2000,
    refresh: bool = False,
) -> xr.Dataset:
    """Linearised BCMD of an isostatic ellipse packing against its exact jamming simplex.

    Donev 2006, sec. 6.4.3 (module docstring). Defaults are the published run: delta = 1e-4,
    Delta mu_max = 1.5e-2, gamma_0 = 0.001, theta = 0.5.

    Parameters
    ----------
    packing : Packing
        A jammed periodic 2D ellipse packing (unshrunk).
    delta : float, default 1e-4
        Relative shrink of the particles, in (0, 0.01).
    contact_tol : float, default 1e-6
        Contacts are the pairs with mu - 1 <= contact_tol, in (0, delta).
    fixed_translation, fixed_rotation : sequence of int
        Frozen centroids and orientations (:func:`hardpack.freeenergy.ellipses.freeze_to_isostatic`
        chooses them for an isostatic simplex).
    dmu_max : float, default 1.5e-2
        Initial cell size, above the disjoint-cell point (about delta).
    gamma0 : float, default 1e-3
        Shrink rate at dmu_max, > 0.
    theta : float, default 0.5
        Exponent of the rate schedule, >= 0.
    seed : int, default 0
        Seed of the initial velocities.
    equilibration : float, default 50.0
        Run time at fixed dmu_max before shrinking, in units of dmu_max times the mean semiaxis
        (thermal speed 1), as in :func:`hardpack.freeenergy.bcmd.run_bcmd`.
    segment_fraction : float, default 0.01
        Relative fall of Delta mu per segment, in (0, 0.5].
    max_events : int
        Bound on the events of one segment.
    refresh : bool, default False
        Re-draw the velocity directions at fixed kinetic energy at every segment boundary and 50
        times during the equilibration. This leaves the microcanonical ensemble and K unchanged
        (so the estimator too) and forces mixing, which the linearised dynamics may lack: flat
        contact planes make a polyhedral billiard (Donev 2006, sec. 6.3.3: ergodicity is
        plausible only with semi-dispersing walls). Off by default (plain MD, as published).
    n_inside_samples : int, default 2000
        Uniform points of the simplex tested against the cells at dmu_max: the fraction inside,
        ``inside_fraction``, gives ``exact_in_cells`` = exact + ln(fraction) / N_eff, the exact
        value of what BCMD measures when the initial cells cut the simplex.

    Returns
    -------
    xarray.Dataset
        Per-segment ``dmu``, ``time``, ``gamma``, ``ln_k``, ``delta_f``, ``events``; attributes
        ``bcmd`` (Delta f), ``exact`` (the reference's Delta f), ``diff``, ``f_j_minus_fcj``, the
        counts, ``vertices_outside`` (simplex vertices outside the cells at dmu_max),
        ``inside_fraction`` (+- ``inside_fraction_err``) and ``exact_in_cells``,
        ``next_gap``, event counts and ``seconds``.

    Raises
    ------
    InvalidInputError
        Invalid packing or parameters, or a packing that is not isostatic with the given frozen
        degrees of freedom.
    RuntimeError
        A segment exceeded ``max_events`` or a particle left its cell or crossed a contact plane.
    """
    clock = time.perf_counter()
    check_ellipsoid_packing(packing)
    delta = _check("delta", delta, hi=1e-2)
    dmu_max, gamma0, theta, equilibration, segment_fraction = _check_schedule(
        dmu_max, gamma0, theta, equilibration, segment_fraction)
    n = packing.n_particles
    free_t, free_r = _free_masks(n, fixed_translation, fixed_rotation)
    _check_round_rotations(packing, free_r)
    ref = ellipse_simplex_reference(packing, delta, contact_tol, fixed_translation, fixed_rotation)
    if ref.isostaticity_gap != 0:
        raise InvalidInputError(
            f"the packing is not isostatic with these frozen particles (M - N_f - 1 = "
            f"{ref.isostaticity_gap}); choose them with freeze_to_isostatic"
        )
    model = linear_model(packing, delta, contact_tol)
    dmu_min = model.dmu_min
    if not dmu_min < dmu_max:
        raise InvalidInputError(f"dmu_max = {dmu_max} must exceed the disjoint-cell point {dmu_min:.6g}")

    net = model.contacts
    axes = model.shrunk.shape.semiaxes
    unit = float(axes.min())
    keep = (free_t | free_r)[net.i] | (free_t | free_r)[net.j]
    ci, cj = net.i[keep].astype(np.int64), net.j[keep].astype(np.int64)
    u = net.normal[keep]
    li, lj = net.lever_i[keep] / unit, net.lever_j[keep] / unit
    ai = -np.column_stack([u, li[:, 0] * u[:, 1] - li[:, 1] * u[:, 0]])
    aj = np.column_stack([u, lj[:, 0] * u[:, 1] - lj[:, 1] * u[:, 0]])
    h = model.gaps[keep] / unit
    im = free_t.astype(float)
    a_scaled = axes / unit
    ii = np.where(free_r, 4.0 / (a_scaled**2).sum(axis=1), 0.0)
    ai[:, :2] *= free_t[ci, None]
    aj[:, :2] *= free_t[cj, None]
    ai[:, 2] *= free_r[ci]
    aj[:, 2] *= free_r[cj]
    phi0 = np.asarray(model.shrunk.shape.orientations, float)
    cell = np.column_stack([np.cos(phi0), np.sin(phi0), a_scaled[:, 0], a_scaled[:, 1]])
    order = np.argsort(np.r_[ci, cj], kind="stable")
    clist = (np.r_[np.arange(len(ci)), np.arange(len(ci))])[order].astype(np.int64)
    start = np.r_[0, np.cumsum(np.bincount(np.r_[ci, cj], minlength=n))].astype(np.int64)

    # simplex vertices against the cells at dmu_max (diagnostic of the comparison's premise)
    free_dof = np.stack([free_t, free_t, free_r], axis=1).ravel()
    rows = np.zeros((len(ci), 3 * n))
    for k in range(3):
        np.add.at(rows, (np.arange(len(ci)), 3 * ci + k), ai[:, k])
        np.add.at(rows, (np.arange(len(ci)), 3 * cj + k), aj[:, k])
    verts = _vertices(-rows[:, free_dof], h)
    full = np.zeros((len(verts), 3 * n))
    full[:, free_dof] = verts
    movers = np.flatnonzero(free_t | free_r)
    vertices_outside = sum(_outside_cells(v.reshape(n, 3), cell, dmu_max, movers) for v in full)
    # the fraction of the simplex inside the cells at dmu_max (uniform points of a simplex are
    # Dirichlet(1, ..., 1) combinations of its vertices)
    rng_in = np.random.default_rng(12345)
    weights = rng_in.dirichlet(np.ones(len(full)), size=n_inside_samples)
    inside = np.array([not _outside_cells((w @ full).reshape(n, 3), cell, dmu_max, movers)
                       for w in weights])
    frac = float(inside.mean())
    frac_err = float(np.sqrt(frac * (1 - frac) / n_inside_samples)) if n_inside_samples else np.nan

    rng = np.random.default_rng(seed)
    n_f = int(free_dof.sum())
    n_eff = int(free_t.sum())
    q = np.zeros((n, 3))
    tq = np.zeros(n)
    mass_inv = np.stack([im, im, ii], axis=1)
    qd = rng.normal(size=(n, 3)) * np.sqrt(mass_inv)

    def kinetic():
        k = 0.0
        for col in range(3):
            ok = mass_inv[:, col] > 0
            k += 0.5 * float(np.sum(qd[ok, col] ** 2 / mass_inv[ok, col]))
        return k

    qd *= np.sqrt(0.5 * n_f / kinetic())
    counts = np.zeros(2, np.int64)
    scale_tol = 1e-12 * delta
    t = 0.0

    def segment(dmu, gamma, duration):
        _, ev = kern.run_segment(q, qd, tq, cell, im, ii, ci, cj, ai, aj, h, start, clist,
                                 t, duration, dmu, gamma, scale_tol, counts, max_events)
        if ev >= max_events:
            raise RuntimeError(f"a segment at dmu = {dmu:.4g} exceeded max_events = {max_events}")

    def redraw():
        k = kinetic()
        qd[:] = rng.normal(size=(n, 3)) * np.sqrt(mass_inv)
        qd[:] *= np.sqrt(k / kinetic())

    t_eq = equilibration * dmu_max * float(a_scaled.mean())
    if t_eq > 0:
        chunks = 50 if refresh else 1
        for _ in range(chunks):
            segment(dmu_max, 0.0, t_eq / chunks)
            t += t_eq / chunks
            if refresh:
                redraw()
    k0 = kinetic()
    rows_out = []
    for dmu, dmu_next, gamma, dt in shrink_schedule(dmu_max, dmu_min, gamma0, theta, segment_fraction):
        ev0 = int(counts.sum())
        segment(dmu, gamma, dt)
        t += dt
        if refresh:
            redraw()
        rows_out.append((dmu_next, t, gamma, np.log(kinetic() / k0), int(counts.sum()) - ev0))
    worst_cell = max(kern.cell_value(i, t, q, qd, tq, cell, dmu_min, 0.0, t)
                     for i in range(n) if free_t[i] or free_r[i])
    gaps_end = h + np.einsum("ck,ck->c", ai, q[ci]) + np.einsum("ck,ck->c", aj, q[cj])
    if worst_cell > 1e-9 * delta or gaps_end.min() < -1e-9 * delta:
        raise RuntimeError(
            f"the final state leaves a cell (max P = {worst_cell:.3g}) or crosses a contact plane "
            f"(min gap {gaps_end.min():.3g}); the event prediction failed"
        )
    arr = np.array(rows_out, dtype=float)
    ln_k = float(arr[-1, 3])
    bcmd = 0.5 * n_f * ln_k / n_eff
    attrs = {
        "hardpack_kind": "bcmd_ellipse", "n_particles": n, "n_contacts": int(len(ci)),
        "n_f": n_f, "n_eff": n_eff, "delta": delta, "contact_tol": contact_tol,
        "fixed_translation": np.asarray(np.flatnonzero(~free_t), np.int64),
        "fixed_rotation": np.asarray(np.flatnonzero(~free_r), np.int64),
        "dmu_max": dmu_max, "dmu_min": dmu_min, "dmu_min_pw": model.dmu_min_pw,
        "gamma0": gamma0, "theta": theta, "seed": int(seed), "equilibration": equilibration,
        "segment_fraction": segment_fraction, "refresh": int(refresh), "bcmd": bcmd, "exact": ref.delta_f,
        "diff": bcmd - ref.delta_f, "f_j_minus_fcj": ref.f_j_minus_fcj, "min_force": ref.min_force,
        "next_gap": model.next_gap, "max_contact_gap": model.max_contact_gap,
        "vertices_outside": int(vertices_outside), "n_vertices": int(len(verts)),
        "inside_fraction": frac, "inside_fraction_err": frac_err,
        "exact_in_cells": ref.delta_f + (np.log(frac) / n_eff if frac > 0 else -np.inf),
        "n_pair": int(counts[0]), "n_wall": int(counts[1]), "n_events": int(counts.sum()),
        "length_unit": unit, "seconds": time.perf_counter() - clock,
    }
    return xr.Dataset(
        {
            "dmu": ("segment", arr[:, 0], {"long_name": "cell size Delta mu at segment end"}),
            "time": ("segment", arr[:, 1]),
            "gamma": ("segment", arr[:, 2]),
            "ln_k": ("segment", arr[:, 3], {"long_name": "ln(K/K0)"}),
            "delta_f": ("segment", 0.5 * n_f * arr[:, 3] / n_eff),
            "events": ("segment", arr[:, 4].astype(np.int64)),
        },
        attrs=attrs,
    )


def disjoint_cells_check(seeds=(1, 2, 3), n: int = 10, dmu0: float = 1e-2, dmu1: float = 1e-3,
                         gamma: float = 3e-4) -> xr.Dataset:
    """The disjoint-cell rung of the ladder for ellipses: ``n`` independent ellipses (aspect
    ratios uniform in [1, 3], random orientations) in cells of their own shape (Eq. C1) shrunk at
    the constant rate ``gamma`` from ``dmu0`` to ``dmu1``. The cell body scales as Delta mu, so
    (3/2) ln(K/K0) = 3 ln(dmu0/dmu1) up to the adiabatic error (the energy of a billiard in a
    homothetically shrinking domain scales as its inverse squared size, ergodic or not).

    Parameters
    ----------
    seeds : sequence of int, optional
        One sample per seed.
    n : int, optional
        Ellipses per sample.
    dmu0, dmu1 : float, optional
        Start and end cell size Delta mu.
    gamma : float, optional
        Shrink rate of the cells.

    Returns
    -------
    xarray.Dataset
        Over ``sample``: ``rel_dev`` = (3/2) ln(K/K0) / (3 ln(dmu0/dmu1)) - 1, ``events``,
        ``seconds``; attributes ``n_particles`` and the parameters.
    """
    rel, events, seconds = [], [], []
    for seed in seeds:
        clock = time.perf_counter()
        rng = np.random.default_rng(seed)
        axes = np.column_stack([rng.uniform(1.0, 3.0, n), np.ones(n)])
        phi0 = rng.uniform(0.0, np.pi, n)
        cell = np.column_stack([np.cos(phi0), np.sin(phi0), axes[:, 0], axes[:, 1]])
        im, ii = np.ones(n), 4.0 / (axes**2).sum(axis=1)
        qd = rng.normal(size=(n, 3)) * np.sqrt(np.column_stack([im, im, ii]))
        q, tq = np.zeros((n, 3)), np.zeros(n)
        none_f, none_i = np.zeros((0, 3)), np.zeros(0, np.int64)
        args = (none_i, none_i, none_f, none_f, np.zeros(0), np.zeros(n + 1, np.int64), none_i)
        counts = np.zeros(2, np.int64)

        def kinetic():
            return 0.5 * (np.sum(qd[:, :2] ** 2) + np.sum(qd[:, 2] ** 2 / ii))

        kern.run_segment(q, qd, tq, cell, im, ii, *args, 0.0, 1.0, dmu0, 0.0, 1e-16, counts, 10**9)
        k0 = kinetic()
        kern.run_segment(q, qd, tq, cell, im, ii, *args, 1.0, (dmu0 - dmu1) / gamma, dmu0, gamma,
                         1e-16, counts, 10**9)
        rel.append(1.5 * np.log(kinetic() / k0) / (3.0 * np.log(dmu0 / dmu1)) - 1.0)
        events.append(int(counts.sum()))
        seconds.append(time.perf_counter() - clock)
    return xr.Dataset(
        {"rel_dev": ("sample", np.array(rel)), "events": ("sample", np.array(events)),
         "seconds": ("sample", np.array(seconds)), "seed": ("sample", np.array(seeds))},
        attrs={"hardpack_kind": "bcmd_ellipse_ladder", "n_particles": n, "dmu0": dmu0, "dmu1": dmu1,
               "gamma": gamma},
    )
