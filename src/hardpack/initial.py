"""Initial configurations: random sequential addition (RSA) of polydisperse spheres in d dimensions.

Radii are drawn from the distribution (systematic sampling, ``numpy.random.default_rng(seed)``) and
placed largest first at uniformly random, non-overlapping positions in a periodic box whose size gives
the target volume fraction, by the one RSA packer of the neighbour layer
(:func:`hardpack.geometry.neighbours.random_sequential_addition`, drawing its uniforms from the same
generator after the radii). The result depends only on (n, d, distribution, phi, box shape, seed).
"""

from __future__ import annotations

import numpy as np

from hardpack.distributions import Discrete, Distribution
from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours import random_sequential_addition
from hardpack.geometry.packing import Packing


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
    positions = random_sequential_addition(radii, box, rng, max_trials)
    species = distribution.species_of(radii) if isinstance(distribution, Discrete) else None
    return Packing(positions, radii, np.diag(box), species=species)
