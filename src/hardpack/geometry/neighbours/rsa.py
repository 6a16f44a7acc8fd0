"""Random sequential addition (RSA) of polydisperse spheres in a periodic orthorhombic box, on the
hierarchical grid.

Spheres are inserted largest first (the usual order for polydisperse RSA; Donev 2006, Sec. 1.2.1, RSA as
the starting state of the LS algorithm) at uniformly random positions; a trial is accepted when the
sphere overlaps (distance < sum of radii, nearest image) no sphere placed so far. Each overlap test is one
query of the hierarchical grid of :mod:`.grid` over all levels (Ogarko's search box, Eq. 2.4, around the
trial position on every level), with linked lists per cell since the spheres arrive one by one. The grid
only decides which placed spheres are tested, never the outcome, so the configuration depends only on
the radii, the box and the random stream: the uniforms are drawn from ``numpy.random.default_rng`` in
fixed-size batches and consumed d per trial, in order, by the numba kernel.

RSA saturates (equal spheres near phi = 0.547, 0.384, 0.260, 0.171, 0.110 for d = 2..6; Torquato, Uche &
Stillinger, Phys. Rev. E 74, 061308 (2006)); wide size distributions placed largest first get much
further (UV omega = 50: phi = 0.6). A sphere that cannot be placed in ``max_trials`` trials makes the call
fail with a message asking for a lower density.
"""

from __future__ import annotations

import numba
import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours.grid import RANGE_PAD, c_strides, cell_counts, next_cell, search_range
from hardpack.geometry.neighbours.levels import optimal_levels

_BATCH = 4096  # trials per batch of uniforms
RSA_SATURATION = {1: 0.747, 2: 0.547, 3: 0.384, 4: 0.260, 5: 0.171, 6: 0.110}


@numba.njit(cache=True)
def _overlaps_any(x, s, r, pos, radii, box, inv_box, level_reach, n_cells, strides, cell_offset, head, nxt,
                  lo, hi, c):
    """True if the sphere (x, r) (fractional position s) overlaps a placed sphere on any level."""
    d = x.shape[0]
    for lv in range(n_cells.shape[0]):
        search_range(s, (r + level_reach[lv]) * (1.0 + RANGE_PAD), inv_box, n_cells, lv, lo, hi)
        for k in range(d):
            if hi[k] - lo[k] + 1 >= n_cells[lv, k]:  # the whole row: each cell once (nearest image)
                lo[k] = 0
                hi[k] = n_cells[lv, k] - 1
            c[k] = lo[k]
        while True:
            flat = cell_offset[lv]
            for k in range(d):
                flat += (c[k] % n_cells[lv, k]) * strides[lv, k]
            q = head[flat]
            while q >= 0:
                dist2 = 0.0
                for k in range(d):
                    dx = x[k] - pos[q, k]
                    dx -= box[k] * np.floor(dx / box[k] + 0.5)
                    dist2 += dx * dx
                t = r + radii[q]
                if dist2 < t * t:
                    return True
                q = nxt[q]
            if not next_cell(c, lo, hi):
                break
    return False


@numba.njit(cache=True)
def _inside(x, r, walled, lo, hi, sphere):
    """True if a sphere of radius r at x lies inside the walls: lo_k + r <= x_k <= hi_k - r on the
    walled axes and |x - c| <= R - r in a container (sphere = (c, R), R < 0: no container)."""
    d = x.shape[0]
    for k in range(d):
        if walled[k] and (x[k] < lo[k] + r or x[k] > hi[k] - r):
            return False
    if sphere[d] >= 0.0:
        dist2 = 0.0
        for k in range(d):
            dist2 += (x[k] - sphere[k]) ** 2
        if dist2 > (sphere[d] - r) ** 2 or sphere[d] < r:
            return False
    return True


@numba.njit(cache=True)
def _rsa_kernel(order, radii, box, level, level_reach, n_cells, strides, cell_offset, head, nxt, pos,
                uniforms, start, trials_done, max_trials, walled, wall_lo, wall_hi, sphere):
    """Place spheres order[start:] with the uniforms in sequence; returns (next, trials of it).
    A trial outside the walls (:func:`_inside`) is rejected like an overlapping one."""
    d = box.shape[0]
    inv_box = 1.0 / box
    x = np.empty(d)
    s = np.empty(d)
    lo = np.empty(d, np.int64)
    hi = np.empty(d, np.int64)
    c = np.empty(d, np.int64)
    used = 0
    trials = trials_done
    i = start
    while i < order.shape[0]:
        if used + d > uniforms.shape[0] or trials >= max_trials:
            return i, trials
        p = order[i]
        for k in range(d):
            x[k] = uniforms[used + k] * box[k]
            s[k] = x[k] / box[k]
        used += d
        trials += 1
        if _inside(x, radii[p], walled, wall_lo, wall_hi, sphere) and \
                not _overlaps_any(x, s, radii[p], pos, radii, box, inv_box, level_reach, n_cells, strides,
                                  cell_offset, head, nxt, lo, hi, c):
            h = level[p]
            flat = cell_offset[h]
            for k in range(d):
                pos[p, k] = x[k]
                flat += min(int(s[k] * n_cells[h, k]), n_cells[h, k] - 1) * strides[h, k]
            nxt[p] = head[flat]
            head[flat] = p
            i += 1
            trials = 0
    return i, trials


def random_sequential_addition(radii, box, seed, max_trials: int = 100_000, walled=None,
                               container=None) -> np.ndarray:
    """Positions (N, d) in [0, box) for these radii, placed largest first (stable order of decreasing
    radius); deterministic in ``seed`` (an integer, or a ``numpy.random.Generator`` to draw from).

    box: (d,) side lengths of the orthorhombic box, each at least two largest diameters; periodic
    unless ``walled`` (d,) bools mark axes with hard walls at 0 and box_k, or ``container`` =
    (centre, R) puts a hard spherical container inside the box (no axis periodic). With walls the
    trials are drawn in a periodic box padded by two largest diameters along the walled axes (so no
    periodic image can reach a sphere inside the walls) and rejected outside the walls.
    Raises InvalidInputError when a sphere cannot be placed in ``max_trials`` trials (the density is
    above RSA saturation for these radii).

    Parameters
    ----------
    radii : array_like of float, shape (N,)
        Positive radii.
    box : array_like of float, shape (d,)
        Box side lengths.
    seed : int or numpy.random.Generator
        Random source.
    max_trials : int, optional
        Trials per sphere before giving up.
    walled : array_like of bool, shape (d,), optional
        Axes with hard walls.
    container : tuple of (array_like of float, shape (d,), float), optional
        Centre and radius of a spherical container.

    Returns
    -------
    numpy.ndarray of float, shape (N, d)
        The positions, in the input order of ``radii``.

    Raises
    ------
    InvalidInputError
        For bad input or when a sphere cannot be placed.
    """
    r = np.asarray(radii, dtype=float)
    box = np.asarray(box, dtype=float)
    if r.ndim != 1 or r.size == 0 or not (np.isfinite(r).all() and (r > 0).all()):
        raise InvalidInputError("radii must be a non-empty 1-d array of positive finite values")
    d = box.size
    if box.shape != (d,) or not (np.isfinite(box).all() and (box > 0).all()):
        raise InvalidInputError(f"box must be positive finite side lengths, got {box!r}")
    if isinstance(max_trials, bool) or int(max_trials) != max_trials or max_trials < 1:
        raise InvalidInputError(f"max_trials must be a positive integer, got {max_trials!r}")
    phi = float(ball_volume(r, d).sum() / np.prod(box))
    if 4 * r.max() > box.min():
        raise InvalidInputError(
            f"the box (side {box.min():.3g}) is smaller than two largest diameters ({4 * r.max():.3g}) "
            f"at phi = {phi:.4g}: use more particles or a lower phi"
        )
    walled = np.zeros(d, np.int8) if walled is None else np.asarray(walled, np.int8)
    sphere = -np.ones(d + 1)
    if container is not None:
        walled[:] = 1
        sphere[:d] = container[0]
        sphere[d] = container[1]
    pad = 4.0 * r.max() * walled
    wall_lo = 0.5 * pad
    wall_hi = 0.5 * pad + box
    sphere[:d] += 0.5 * pad if container is not None else 0.0
    box = box + pad
    levels = optimal_levels(r, float(np.prod(box)), d)
    level = levels.level.astype(np.int64)
    level_reach = 0.5 * levels.cell_sizes
    n_cells = cell_counts(box, levels.cell_sizes, np.bincount(level, minlength=levels.n_levels),
                          max_cells_per_particle=4.0)
    cell_offset = np.concatenate([[0], np.cumsum(np.prod(n_cells, axis=1))]).astype(np.int64)
    head = -np.ones(int(cell_offset[-1]), np.int64)
    nxt = -np.ones(r.size, np.int64)
    order = np.argsort(-r, kind="stable")
    pos = np.zeros((r.size, d))
    rng = np.random.default_rng(seed)
    placed, trials = 0, 0
    while placed < r.size:
        placed, trials = _rsa_kernel(order, r, box, level, level_reach, n_cells, c_strides(n_cells),
                                     cell_offset, head, nxt, pos, rng.random(_BATCH * d), placed, trials,
                                     int(max_trials), walled, wall_lo, wall_hi, sphere)
        if trials >= max_trials:
            raise InvalidInputError(
                f"random sequential addition could not place sphere {placed} of {r.size} (radius "
                f"{r[order[placed]]:.4g}) in {max_trials} trials at phi = {phi:.4g} in d = {d}: above RSA "
                f"saturation for these radii (RSA saturates near {RSA_SATURATION.get(d, 'less than 0.1')} "
                f"in d = {d} for equal spheres); choose a lower initial phi"
            )
    return pos - wall_lo
