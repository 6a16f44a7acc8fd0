"""Initial configurations: random sequential addition (RSA) of polydisperse spheres in d dimensions.

Radii are drawn from the distribution (systematic sampling, ``numpy.random.default_rng(seed)``) and
placed largest first at uniformly random, non-overlapping positions in a periodic box whose size gives
the target volume fraction, by the one RSA packer of the neighbour layer
(:func:`hardpack.geometry.neighbours.random_sequential_addition`, drawing its uniforms from the same
generator after the radii). The result depends only on (n, d, distribution, phi, box shape, seed).

Finite containers (Donev 2006, Ch. 7): ``boundary="hard_walls"`` puts hard walls at 0 and L_k on
``wall_axes`` (all axes by default) of the same box; ``boundary="spherical_container"`` places the
spheres inside a spherical container of radius R, V_d(R) = (particle volume) / phi, centred in the
cube [0, 2R]^d (the pseudo-box of the MD cell lists). Positions are uniform over the region each
centre can reach (RSA restricted to the container).
"""

from __future__ import annotations

import numpy as np

from hardpack.distributions import Discrete, Distribution
from hardpack.errors import InvalidInputError, check_seed
from hardpack.geometry.balls import ball_volume, unit_ball_volume
from hardpack.geometry.boundaries import HardWalls, SphericalContainer
from hardpack.geometry.neighbours import random_sequential_addition
from hardpack.geometry.packing import Packing


def random_packing(n: int, d: int, distribution: Distribution, phi: float, seed: int,
                   box_shape=None, max_trials: int = 100_000, boundary: str = "periodic",
                   wall_axes=None) -> Packing:
    """Seeded RSA packing of ``n`` spheres with radii from ``distribution`` at volume fraction ``phi``.

    Parameters
    ----------
    n : int
        Number of spheres, >= 1.
    d : int
        Dimension, 1 to 12.
    distribution : hardpack.distributions.Distribution
        Size distribution of the radii (systematic sampling; placed largest first).
    phi : float
        Volume fraction in (0, 1) over the boundary's volume; RSA saturates well below jamming.
    seed : int
        Seed of ``numpy.random.default_rng`` (radii first, then the positions).
    box_shape : sequence of d floats, optional
        Relative box lengths (default a cube; not with a spherical container).
    max_trials : int, default 100000
        Trials per sphere before giving up.
    boundary : {"periodic", "hard_walls", "spherical_container"}
        A periodic box, hard walls on ``wall_axes`` of the box, or a spherical container (module
        docstring).
    wall_axes : sequence of int, optional
        The walled axes with ``boundary="hard_walls"`` (default all).

    Returns
    -------
    Packing
        The spheres, with species labels for discrete distributions, checked for overlaps and
        containment by the packing model.

    Raises
    ------
    InvalidInputError
        For a bad n, d, phi, seed, distribution, box shape, boundary or wall axes, a container
        smaller than the largest sphere, or when RSA cannot place a sphere.
    """
    if int(n) != n or n < 1:
        raise InvalidInputError(f"n must be a positive integer, got {n!r}")
    if int(d) != d or not 1 <= d <= 12:
        raise InvalidInputError(f"d must be an integer in 1..12, got {d!r}")
    if not (np.isfinite(phi) and 0 < phi < 1):
        raise InvalidInputError(f"phi must be in (0, 1), got {phi!r}")
    check_seed(seed)
    if not isinstance(distribution, Distribution):
        raise InvalidInputError(f"distribution must be a hardpack Distribution, got {type(distribution).__name__}")
    n, d = int(n), int(d)
    rng = np.random.default_rng(seed)
    radii = distribution.sample(n, rng)[::-1].copy()  # largest first
    shape = np.ones(d) if box_shape is None else np.asarray(box_shape, float)
    if shape.shape != (d,) or not (np.isfinite(shape).all() and (shape > 0).all()):
        raise InvalidInputError(f"box_shape must be {d} positive numbers, got {box_shape!r}")
    if boundary not in ("periodic", "hard_walls", "spherical_container"):
        raise InvalidInputError(f"boundary must be 'periodic', 'hard_walls' or 'spherical_container', "
                                f"got {boundary!r}")
    if wall_axes is not None and boundary != "hard_walls":
        raise InvalidInputError("wall_axes is for boundary='hard_walls' only")
    species = distribution.species_of(radii) if isinstance(distribution, Discrete) else None
    volume = ball_volume(radii, d).sum() / phi
    if boundary == "spherical_container":
        if box_shape is not None:
            raise InvalidInputError("a spherical container sits in a cube: leave box_shape unset")
        radius = (volume / unit_ball_volume(d)) ** (1.0 / d)
        if radius < radii.max():
            raise InvalidInputError(f"phi = {phi:g} leaves a container (radius {radius:.4g}) smaller than "
                                    f"the largest sphere (radius {radii.max():.4g}): lower phi")
        box = np.full(d, 2.0 * radius)
        container = SphericalContainer(tuple(box / 2), radius)
        positions = random_sequential_addition(radii, box, rng, max_trials,
                                               container=(np.asarray(container.centre), radius))
        return Packing(positions, radii, np.diag(box), species=species, boundary=container)
    box = shape * (volume / np.prod(shape)) ** (1.0 / d)
    if boundary == "periodic":
        positions = random_sequential_addition(radii, box, rng, max_trials)
        return Packing(positions, radii, np.diag(box), species=species)
    walls = HardWalls(tuple(range(d)) if wall_axes is None else wall_axes)
    walls.check(np.diag(box))
    walled = np.zeros(d, dtype=bool)
    walled[list(walls.axes)] = True
    positions = random_sequential_addition(radii, box, rng, max_trials, walled=walled)
    return Packing(positions, radii, np.diag(box), species=species, boundary=walls)


def random_ellipsoid_packing(n: int, semiaxes, phi: float, seed: int, box_shape=None,
                             max_trials: int = 100_000, boundary: str = "periodic", wall_axes=None) -> Packing:
    """Seeded RSA packing of ``n`` ellipsoids (or ellipses) with random orientations at volume fraction ``phi``.

    The particles are placed largest bounding radius first (a stable sort, so equal particles keep
    their order) at uniformly random positions and orientations by
    :func:`hardpack.geometry.ellipsoid_rsa.ellipsoid_rsa` (Perram-Wertheim overlap test, Donev 2006,
    Sec. 2.2.2), in a periodic box whose size gives ``phi``. The result depends only on the arguments.

    With ``boundary="spherical_container"`` (Donev 2006, Ch. 7) the particles fill a spherical
    container of volume (particle volume) / phi centred in a cube of side 2 R: a dilute random start
    whose bounding spheres (radius the largest semiaxis) are placed by sphere RSA inside the
    container (as :func:`random_packing`), with uniformly random orientations, so that no two
    particles overlap and every particle is inside; the bounding spheres fill phi times the mean
    a_max^d / prod a, which must stay below RSA saturation (e.g. phi <= 0.15 for aspect ratio 2).
    With ``boundary="hard_walls"`` (Donev 2006, sec. 3.2.2.1) the box of ``box_shape`` has hard
    walls at 0 and L_k on ``wall_axes`` (all axes by default), and the start is made the same way:
    bounding spheres by sphere RSA between the walls, uniformly random orientations.

    Parameters
    ----------
    n : int
        Number of particles, >= 1.
    semiaxes : array_like, shape (d,) or (n, d), d = 2 or 3
        Body-frame semiaxes of every particle (one row for all, or one per particle).
    phi : float
        Volume fraction in (0, 1); RSA saturates well below jamming, so keep it low (e.g. <= 0.3).
    seed : int
        Seed of ``numpy.random.default_rng``.
    box_shape : sequence of d floats, optional
        Relative box lengths (default a cube; not with a spherical container).
    max_trials : int, default 100000
        Trials per particle before giving up.
    boundary : {"periodic", "hard_walls", "spherical_container"}
        A periodic cell, hard walls or a spherical container (above); phi is over the boundary's volume.
    wall_axes : sequence of int, optional
        The walled axes with ``boundary="hard_walls"`` (default all).

    Returns
    -------
    Packing
        Ellipsoids in a periodic orthorhombic cell, between hard walls or in a spherical container,
        checked for overlaps and containment by the packing model.

    Raises
    ------
    InvalidInputError
        For a bad n, semiaxes, phi, seed or box shape, or when RSA cannot place a particle.
    """
    from hardpack.geometry.ellipsoid_rsa import ellipsoid_rsa
    from hardpack.geometry.shapes import ELLIPSOID_DIMS, Ellipsoids, as_finite_array

    if isinstance(n, bool) or int(n) != n or n < 1:
        raise InvalidInputError(f"n must be a positive integer, got {n!r}")
    n = int(n)
    axes = as_finite_array("semiaxes", semiaxes, "(d,) or (n, d)")
    if axes.ndim == 1:
        axes = np.tile(axes, (n, 1))
    if axes.ndim != 2 or axes.shape[0] != n or axes.shape[1] not in ELLIPSOID_DIMS or not (axes > 0).all():
        raise InvalidInputError(f"semiaxes must be positive, of shape (d,) or ({n}, d) with d in {ELLIPSOID_DIMS}, "
                                f"got {np.shape(semiaxes)}")
    d = axes.shape[1]
    if not (np.isfinite(phi) and 0 < phi < 1):
        raise InvalidInputError(f"phi must be in (0, 1), got {phi!r}")
    check_seed(seed)
    shape = np.ones(d) if box_shape is None else np.asarray(box_shape, float)
    if shape.shape != (d,) or not (np.isfinite(shape).all() and (shape > 0).all()):
        raise InvalidInputError(f"box_shape must be {d} positive numbers, got {box_shape!r}")
    if boundary not in ("periodic", "hard_walls", "spherical_container"):
        raise InvalidInputError(f"boundary must be 'periodic', 'hard_walls' or 'spherical_container', "
                                f"got {boundary!r}")
    if wall_axes is not None and boundary != "hard_walls":
        raise InvalidInputError("wall_axes is for boundary='hard_walls' only")
    axes = axes[np.argsort(-axes.max(axis=1), kind="stable")]
    volume = Ellipsoids(axes, np.zeros(n) if d == 2 else np.tile([1.0, 0, 0, 0], (n, 1))).volumes(d).sum()
    if boundary == "spherical_container":
        if box_shape is not None:
            raise InvalidInputError("a spherical container sits in a cube: leave box_shape unset")
        return _ellipsoids_in_a_container(axes, volume / phi, phi, np.random.default_rng(seed), max_trials)
    box = shape * (volume / (phi * np.prod(shape))) ** (1.0 / d)
    if boundary == "hard_walls":
        return _ellipsoids_between_walls(axes, box, phi, wall_axes, np.random.default_rng(seed), max_trials)
    positions, orientations = ellipsoid_rsa(axes, box, np.random.default_rng(seed), max_trials)
    return Packing(positions, lattice=np.diag(box), shape=Ellipsoids(axes, orientations))


def _random_orientations(rng, n: int, d: int) -> np.ndarray:
    """Uniformly random angles (2D) or unit quaternions (3D, normalised Gaussians)."""
    if d == 2:
        return rng.uniform(0.0, 2.0 * np.pi, n)
    orientations = rng.standard_normal((n, 4))
    return orientations / np.linalg.norm(orientations, axis=1, keepdims=True)


def _ellipsoids_between_walls(axes: np.ndarray, box: np.ndarray, phi: float, wall_axes, rng,
                              max_trials: int) -> Packing:
    """Dilute random start of :func:`random_ellipsoid_packing` between hard walls: bounding spheres
    by RSA inside the walls (periodic along the other axes), random orientations."""
    from hardpack.geometry.shapes import Ellipsoids

    n, d = axes.shape
    walls = HardWalls(tuple(range(d)) if wall_axes is None else wall_axes)
    walls.check(np.diag(box))
    walled = np.zeros(d, dtype=bool)
    walled[list(walls.axes)] = True
    bound = axes.max(axis=1)
    if (box[walled] < 2.0 * bound.max()).any():
        raise InvalidInputError(f"phi = {phi:g} leaves a walled box side ({box[walled].min():.4g}) shorter than "
                                f"the largest particle (largest semiaxis {bound.max():.4g}): lower phi")
    try:
        positions = random_sequential_addition(bound, box, rng, max_trials, walled=walled)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{exc}. The start places the bounding spheres (phi {phi:g} times "
                                f"{float(np.mean(bound**d / axes.prod(axis=1))):.3g}): lower phi") from exc
    return Packing(positions, lattice=np.diag(box), shape=Ellipsoids(axes, _random_orientations(rng, n, d)),
                   boundary=walls)


def _ellipsoids_in_a_container(axes: np.ndarray, volume: float, phi: float, rng, max_trials: int) -> Packing:
    """Dilute random start of :func:`random_ellipsoid_packing` in a spherical container of ``volume``:
    bounding spheres by RSA inside it, random orientations."""
    from hardpack.geometry.shapes import Ellipsoids

    n, d = axes.shape
    radius = (volume / unit_ball_volume(d)) ** (1.0 / d)
    bound = axes.max(axis=1)
    if radius < bound.max():
        raise InvalidInputError(f"phi = {phi:g} leaves a container (radius {radius:.4g}) smaller than the "
                                f"largest particle (largest semiaxis {bound.max():.4g}): lower phi")
    box = np.full(d, 2.0 * radius)
    container = SphericalContainer(tuple(box / 2), radius)
    try:
        positions = random_sequential_addition(bound, box, rng, max_trials,
                                               container=(np.asarray(container.centre), radius))
    except InvalidInputError as exc:
        raise InvalidInputError(f"{exc}. The start places the bounding spheres (phi {phi:g} times "
                                f"{float(np.mean(bound**d / axes.prod(axis=1))):.3g}): lower phi") from exc
    return Packing(positions, lattice=np.diag(box), shape=Ellipsoids(axes, _random_orientations(rng, n, d)),
                   boundary=container)
