"""Initial configurations: random sequential addition (RSA) of polydisperse spheres in d dimensions.

Spheres are inserted largest first (the usual order for polydisperse RSA, Donev ch. 1.2.1: "random
sequential addition" as the LS starting state) at uniformly random, non-overlapping positions in a
periodic box whose size gives the target volume fraction. A cell grid (cell side >= the largest
diameter) makes each trial O(3^d) cell visits, so insertion is O(N) overall at low density.
Randomness comes from ``numpy.random.default_rng(seed)`` drawn in Python in fixed-size batches and
consumed in order by the numba kernel, so the result depends only on (n, d, distribution, phi,
seed). RSA saturates (monodisperse saturation densities ~0.547, 0.384, 0.260, 0.171, 0.110 for
d = 2..6, Torquato, Uche & Stillinger, PRE 74, 061308 (2006)); if a sphere cannot be placed in
``max_trials`` attempts the call fails with a message suggesting a lower phi.
"""

from __future__ import annotations

import itertools

import numba
import numpy as np

from hardpack.distributions import Discrete, Distribution
from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.packing import Packing

_BATCH = 4096
_RSA_SATURATION = {1: 0.747, 2: 0.547, 3: 0.384, 4: 0.260, 5: 0.171, 6: 0.110}


@numba.njit(cache=True)
def _cell_of(x, box, ncell):
    c = 0
    stride = 1
    for k in range(x.shape[0]):
        ck = int(x[k] / box[k] * ncell[k])
        if ck >= ncell[k]:
            ck = ncell[k] - 1
        c += ck * stride
        stride *= ncell[k]
    return c


@numba.njit(cache=True)
def _rsa_kernel(radii, box, ncell, offsets, uniforms, positions, head, nxt, start, trials_done, max_trials):
    """Place spheres start.. using the uniforms in order; return (next sphere, uniforms used, trials).

    Stops early (returning the counters) when the uniforms run out or a sphere exceeds max_trials.
    """
    n, d = positions.shape
    used = 0
    i = start
    trials = trials_done
    xk = np.empty(d)
    cell = np.empty(d, np.int64)
    while i < n:
        if used + d > uniforms.shape[0] or trials >= max_trials:
            return i, used, trials
        for k in range(d):
            xk[k] = uniforms[used + k] * box[k]
        used += d
        trials += 1
        for k in range(d):
            ck = int(xk[k] / box[k] * ncell[k])
            cell[k] = ck if ck < ncell[k] else ncell[k] - 1
        ok = True
        for o in range(offsets.shape[0]):
            c = 0
            stride = 1
            for k in range(d):
                c += ((cell[k] + offsets[o, k]) % ncell[k]) * stride
                stride *= ncell[k]
            j = head[c]
            while j >= 0:
                dist2 = 0.0
                for k in range(d):
                    dx = xk[k] - positions[j, k]
                    dx -= box[k] * np.floor(dx / box[k] + 0.5)
                    dist2 += dx * dx
                s = radii[i] + radii[j]
                if dist2 < s * s:
                    ok = False
                    break
                j = nxt[j]
            if not ok:
                break
        if ok:
            for k in range(d):
                positions[i, k] = xk[k]
            c = _cell_of(xk, box, ncell)
            nxt[i] = head[c]
            head[c] = i
            i += 1
            trials = 0
    return i, used, trials


def random_packing(n: int, d: int, distribution: Distribution, phi: float, seed: int,
                   box_shape=None, max_trials: int = 100_000) -> Packing:
    """Seeded RSA packing of ``n`` spheres with radii from ``distribution`` at volume fraction ``phi``.

    ``box_shape`` gives relative box lengths (default a cube). Species labels are set for
    discrete distributions. Raises :class:`InvalidInputError` for impossible requests.
    """
    if int(n) != n or n < 1:
        raise InvalidInputError(f"n must be a positive integer, got {n!r}")
    if int(d) != d or not 1 <= d <= 12:
        raise InvalidInputError(f"d must be an integer in 1..12, got {d!r}")
    if not (np.isfinite(phi) and 0 < phi < 1):
        raise InvalidInputError(f"phi must be in (0, 1), got {phi!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError(f"seed must be a non-negative integer, got {seed!r}")
    if not isinstance(distribution, Distribution):
        raise InvalidInputError(f"distribution must be a hardpack Distribution, got {type(distribution).__name__}")
    n, d = int(n), int(d)
    rng = np.random.default_rng(seed)
    radii = distribution.sample(n, rng)[::-1].copy()  # largest first
    shape = np.ones(d) if box_shape is None else np.asarray(box_shape, float)
    if shape.shape != (d,) or not (np.isfinite(shape).all() and (shape > 0).all()):
        raise InvalidInputError(f"box_shape must be {d} positive numbers, got {box_shape!r}")
    scale = (ball_volume(radii, d).sum() / (phi * np.prod(shape))) ** (1.0 / d)
    box = shape * scale
    if 4 * radii[0] > box.min():
        raise InvalidInputError(
            f"the box (side {box.min():.3g}) is smaller than two largest diameters ({4 * radii[0]:.3g}) "
            f"at phi = {phi}: use more particles or a lower phi"
        )
    ncell = np.maximum(1, np.floor(box / (2 * radii[0]))).astype(np.int64)
    per_dim = [(-1, 0, 1) if m >= 3 else tuple(range(m)) for m in ncell]
    offsets = np.array(list(itertools.product(*per_dim)), dtype=np.int64)
    positions = np.zeros((n, d))
    head = -np.ones(int(np.prod(ncell)), dtype=np.int64)
    nxt = -np.ones(n, dtype=np.int64)
    placed, trials = 0, 0
    while placed < n:
        uniforms = rng.random(_BATCH * d)
        placed, _, trials = _rsa_kernel(
            radii, box, ncell, offsets, uniforms, positions, head, nxt, placed, trials, max_trials
        )
        if trials >= max_trials:
            raise InvalidInputError(
                f"random sequential addition could not place sphere {placed} of {n} after "
                f"{max_trials} trials at phi = {phi} in d = {d}: RSA saturates well below jamming "
                f"(near {_RSA_SATURATION.get(d, 'less than 0.1')} in d = {d}); choose a lower initial phi"
            )
    species = distribution.species_of(radii) if isinstance(distribution, Discrete) else None
    return Packing(positions, radii, np.diag(box), species=species)
