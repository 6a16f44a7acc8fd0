"""Random sequential addition (RSA) of ellipsoids or ellipses in a periodic orthorhombic box.

Particles are inserted in the given order at uniformly random positions with uniformly random
orientations (quaternions normalised from four standard normals, i.e. uniform rotations, in 3D;
uniform angles in 2D). A trial is accepted when its Perram-Wertheim potential zeta
(:func:`hardpack.geometry.contact.pw_contact`) is positive with every particle placed so far whose
bounding sphere it meets, over the nearest image or, in a box narrower than four bounding radii,
over every image within reach (its own images included). The trials are drawn from
``numpy.random.default_rng`` in batches of fixed size and consumed in order (d uniforms, then 4
normals or 1 uniform for the orientation per trial), so the result depends only on the semiaxes, the
box and the generator's state.
"""

from __future__ import annotations

import numba
import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.contact import pw_contact, shape_inverse

_BATCH = 4096  # trials per batch of random numbers


@numba.njit(cache=True)
def _fits(x, inv_c, r_c, pos, inv, bound, placed, box, reach):
    """True if the trial particle (centre x, X^-1 inv_c, bounding radius r_c) overlaps no placed one,
    checking lattice images -reach..reach around the nearest image along every axis."""
    d = x.shape[0]
    dx = np.empty(d)
    r = np.empty(d)
    n_img = (2 * reach + 1) ** d
    for q in range(placed + 1):  # q == placed: the particle's own images
        for img in range(n_img):
            code = img
            zero = True
            for k in range(d):
                shift = code % (2 * reach + 1) - reach
                code //= 2 * reach + 1
                if q < placed:
                    dx[k] = pos[q, k] - x[k]
                    dx[k] -= box[k] * np.floor(dx[k] / box[k] + 0.5)
                else:
                    dx[k] = 0.0
                r[k] = dx[k] + shift * box[k]
                if shift != 0:
                    zero = False
            if q == placed and zero:
                continue
            r_q = bound[q] if q < placed else r_c
            dist2 = 0.0
            for k in range(d):
                dist2 += r[k] * r[k]
            if dist2 >= (r_c + r_q) * (r_c + r_q):
                continue
            inv_q = inv[q] if q < placed else inv_c
            zeta, _, _ = pw_contact(r, inv_c, inv_q, r_c / (r_c + r_q))
            if zeta <= 0.0:
                return False
    return True


@numba.njit(cache=True)
def _place(semiaxes, bound, box, reach, uniforms, orient_draws, pos, orient, inv, placed, tries, max_trials):
    """Consume one batch of trials; returns (particles placed, trials of the current particle)."""
    n, d = semiaxes.shape
    inv_c = np.empty((d, d))
    row = np.empty(orient.shape[1])
    x = np.empty(d)
    for t in range(uniforms.shape[0]):
        if placed == n or tries >= max_trials:
            break
        for k in range(d):
            x[k] = uniforms[t, k] * box[k]
        if d == 2:
            row[0] = np.pi * (2.0 * orient_draws[t, 0] - 1.0)
        else:
            norm = np.sqrt(np.sum(orient_draws[t] ** 2))
            for k in range(4):
                row[k] = orient_draws[t, k] / norm
        shape_inverse(semiaxes[placed], row, inv_c)
        tries += 1
        if _fits(x, inv_c, bound[placed], pos, inv, bound, placed, box, reach):
            pos[placed] = x
            orient[placed] = row
            inv[placed] = inv_c
            placed += 1
            tries = 0
    return placed, tries


def ellipsoid_rsa(semiaxes: np.ndarray, box: np.ndarray, rng: np.random.Generator,
                  max_trials: int = 100_000) -> tuple[np.ndarray, np.ndarray]:
    """Centres and orientations of the ellipsoids ``semiaxes`` placed by RSA in the periodic ``box``.

    Parameters
    ----------
    semiaxes : ndarray, shape (N, d), d = 2 or 3
        Body-frame semiaxes, inserted in this order.
    box : ndarray, shape (d,)
        Side lengths of the periodic orthorhombic box.
    rng : numpy.random.Generator
        Source of the trials (module docstring).
    max_trials : int, default 100000
        Trials allowed for one particle before giving up.

    Returns
    -------
    positions : ndarray, shape (N, d)
        Centres in [0, box).
    orientations : ndarray, shape (N, 4) in 3D or (N,) in 2D
        Unit quaternions or angles in radians.

    Raises
    ------
    InvalidInputError
        If a particle cannot be placed in ``max_trials`` trials (the density is too high for RSA).
    """
    n, d = semiaxes.shape
    bound = semiaxes.max(axis=1)
    reach = 0 if box.min() >= 4.0 * bound.max() else int(np.ceil(2.0 * bound.max() / box.min())) + 1
    m = 4 if d == 3 else 1
    pos, orient, inv = np.empty((n, d)), np.empty((n, m)), np.empty((n, d, d))
    placed = tries = 0
    while placed < n:
        uniforms = rng.random((_BATCH, d))
        draws = rng.standard_normal((_BATCH, 4)) if d == 3 else rng.random((_BATCH, 1))
        placed, tries = _place(semiaxes, bound, box, reach, uniforms, draws, pos, orient, inv, placed, tries,
                               max_trials)
        if tries >= max_trials:
            raise InvalidInputError(
                f"random sequential addition could not place ellipsoid {placed} of {n} in {max_trials} "
                "trials: the volume fraction is too high for RSA; ask for a lower one"
            )
    return pos, (orient if d == 3 else orient[:, 0])
