"""Random sequential addition (RSA) of very polydisperse spheres with the hierarchical grid.

Same protocol as :func:`hardpack.initial.random_packing` (largest sphere first, uniform random
trial positions in a periodic box, a trial is accepted when it overlaps nothing placed so far), but
each overlap test is one HGrid query over all levels (:func:`hardpack.hgrid.search.overlaps_any`)
instead of a scan of a single grid with cells of the largest diameter. For wide distributions
(UV omega = 50: ~1e3 particles per top-size cell at phi = 0.6) that is the difference between
minutes and seconds. Largest-first RSA of wide distributions reaches high densities (UV omega = 50,
N = 1e5: phi = 0.6 is reachable), which makes it a direct construction of the dense benchmark
configurations of ch. 2.1 (phi = 0.62 there, from DEM). The configurations carry RSA's pair
correlations, not those of an equilibrated or jammed packing.
"""

from __future__ import annotations

import numba
import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.hgrid.search import insert, overlaps_any, plan

_BATCH = 1 << 16


@numba.njit(cache=True)
def _rsa_kernel(order, radii, box, ncell, head_offset, reach, level, head, nxt, pos, uniforms,
                start, trials_done, max_trials):
    """Place spheres order[start:] with the uniforms in sequence; returns (next, trials of it)."""
    d = box.shape[0]
    x = np.empty(d)
    cell = np.empty(d, np.int64)
    used = 0
    trials = trials_done
    i = start
    while i < order.shape[0]:
        if used + d > uniforms.shape[0] or trials >= max_trials:
            return i, trials
        p = order[i]
        for k in range(d):
            x[k] = uniforms[used + k] * box[k]
        used += d
        trials += 1
        if not overlaps_any(x, radii[p], pos, radii, box, ncell, head_offset, reach, head, nxt):
            for k in range(d):
                pos[p, k] = x[k]
            insert(p, pos, box, ncell, head_offset, level, head, nxt, cell)
            i += 1
            trials = 0
    return i, trials


def random_sequential_addition(radii, box, seed: int, max_trials: int = 100_000) -> np.ndarray:
    """Positions (N, d) in [0, box) for these radii, placed largest first; deterministic in ``seed``.

    box: (d,) side lengths of the periodic orthorhombic box (at least 3 largest diameters each).
    Raises InvalidInputError when a sphere cannot be placed in ``max_trials`` trials (the density is
    above RSA saturation for this distribution).
    """
    r = np.asarray(radii, dtype=float)
    grid = plan(r, box)
    if int(max_trials) != max_trials or max_trials < 1:
        raise InvalidInputError(f"max_trials must be a positive integer, got {max_trials!r}")
    order = np.argsort(-r, kind="stable")
    head, nxt = grid.empty_lists()
    pos = np.zeros((r.size, grid.box.size))
    rng = np.random.default_rng(seed)
    placed, trials = 0, 0
    while placed < r.size:
        placed, trials = _rsa_kernel(order, r, grid.box, grid.ncell, grid.head_offset, grid.reach, grid.level,
                                     head, nxt, pos, rng.random(_BATCH * grid.box.size), placed, trials,
                                     int(max_trials))
        if trials >= max_trials:
            phi = ball_volume(r, grid.box.size).sum() / np.prod(grid.box)
            raise InvalidInputError(
                f"RSA could not place sphere {placed} of {r.size} (radius {r[order[placed]]:.4g}) in "
                f"{max_trials} trials (volume fraction {phi:.4g}): above RSA saturation; lower the density"
            )
    return pos
