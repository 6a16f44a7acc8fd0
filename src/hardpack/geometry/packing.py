"""The packing model: N hard particles in d dimensions in a cell with a boundary.

Conventions (used everywhere in hardpack):

- ``positions`` are Cartesian, shape (N, d).
- ``lattice`` is the d x d matrix whose **columns** are the lattice vectors (Donev's Lambda,
  dissertation ch. 3.2.2.1): a point with fractional coordinates s has Cartesian position
  x = lattice @ s, and the periodic images of x are x + lattice @ n for integer vectors n.
  A general (sheared) lattice is allowed, so strict-jamming tests and SLP can deform the cell.
- ``shape`` describes every particle (:mod:`hardpack.geometry.shapes`): :class:`Spheres` (a radius
  each; ``packing.radii``) or :class:`Ellipsoids` (semiaxes and an orientation each).
  ``Packing(positions, radii, lattice)`` builds spheres; ``Packing(positions, lattice=L,
  shape=Ellipsoids(semiaxes, orientations))`` any other shape.
- ``boundary`` (:mod:`hardpack.geometry.boundaries`) is ``"periodic"`` (every lattice vector is a
  period), :class:`HardWalls` (hard walls on some axes, periodic along the others) or
  :class:`SphericalContainer`. Lattice images exist only along periodic axes.
- ``species`` is an optional integer label per particle (e.g. large/small of a binary mixture).

Only hard spheres in periodic cells are simulated so far; modules that handle nothing else call
:meth:`Packing.require_periodic_spheres`, which refuses other packings by name.

Overlap tolerance: two spheres overlap when their distance is below (r_i + r_j)(1 - tol), a sphere
and a wall when its centre is closer than r (1 - tol) to the wall. The default relative tolerance
``DEFAULT_OVERLAP_TOL = 1e-9`` is far above double-precision round-off after a collision (~1e-14)
and far below any physical gap that matters (LS packings at reduced pressure 1e12 have relative
gaps of ~1e-12 that round-off may turn into overlaps of ~1e-14).

Ellipsoids overlap when their Perram-Wertheim scale factor mu = sqrt(zeta + 1) (Donev 2006,
Sec. 2.2.2.1; :mod:`hardpack.geometry.contact`) is below 1 - tol: the relative overlap 1 - mu is
the sphere's 1 - distance / (r_i + r_j) for equal semiaxes. Candidate pairs are those whose bounding
spheres overlap (:mod:`hardpack.geometry.ellipsoid_pairs`). An ellipsoid crosses a hard wall when
its centre is closer to the wall than (1 - tol) times its extent sqrt(e_k^T X^-1 e_k) along the
wall normal e_k (the distance of the tangent plane, Donev 2006, Sec. 2.2.5.1). An ellipsoid crosses
the wall of a spherical container when its farthest surface point from the container centre is
beyond the wall by more than tol times its largest semiaxis (the exact farthest point of
:mod:`hardpack.geometry.ellipsoid_container`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.boundaries import (
    ContainmentReport,
    HardWalls,
    Periodic,
    SphericalContainer,
    as_boundary,
)
from hardpack.geometry.shapes import Ellipsoids, Spheres, as_finite_array

DEFAULT_OVERLAP_TOL = 1e-9
MIN_DIM, MAX_DIM = 1, 12
SHAPES = (Spheres, Ellipsoids)


@dataclass(frozen=True)
class OverlapReport:
    """Result of an overlap check (:meth:`Packing.overlap_report`): the worst pair and its
    relative overlap.

    Attributes
    ----------
    n_overlapping : int
        Number of pairs (with every periodic image) whose relative overlap exceeds the tolerance.
    worst_i, worst_j : int
        The pair with the largest relative overlap, named even within tolerance; -1 when no pair
        is in contact range.
    shift : tuple of int
        Lattice image n of the worst pair, with separation x_j + lattice @ n - x_i (empty when
        there is no pair).
    overlap : float
        Relative overlap 1 - mu of the worst pair, positive when overlapping: mu = distance /
        (r_i + r_j) for spheres, sqrt(zeta + 1) of the Perram-Wertheim potential for ellipsoids;
        -inf when there is no pair.
    """

    n_overlapping: int
    worst_i: int
    worst_j: int
    shift: tuple
    overlap: float

    def __str__(self) -> str:
        if self.worst_i < 0:
            return "no pairs in contact range"
        return (
            f"{self.n_overlapping} overlapping pair(s); worst: particles {self.worst_i} and "
            f"{self.worst_j} (image {self.shift}) overlap by {self.overlap:.3e} of their contact distance"
        )


def _particle_shape(radii, shape, n: int, d: int):
    """The validated shape of n particles in d dimensions from ``radii`` (spheres) or ``shape``."""
    if shape is None:
        if radii is None:
            raise InvalidInputError("a packing needs radii (for spheres) or shape=... (e.g. "
                                    "hardpack.geometry.Ellipsoids(semiaxes, orientations))")
        shape = Spheres(radii)
    elif radii is not None:
        raise InvalidInputError("give either radii (spheres) or shape, not both")
    elif not isinstance(shape, SHAPES):
        raise InvalidInputError(f"shape must be one of {[c.__name__ for c in SHAPES]} from "
                                f"hardpack.geometry.shapes, got {type(shape).__name__}")
    if shape.n_particles != n:
        arrays = "radii" if shape.kind == "sphere" else "semiaxes and orientations"
        held = shape.radii.shape if shape.kind == "sphere" else (shape.n_particles,)
        raise InvalidInputError(f"{arrays} must have shape ({n},) to match {n} positions, got shape {held}")
    if shape.dim is not None and shape.dim != d:
        raise InvalidInputError(f"the shapes are {shape.dim}-dimensional ({shape.dim} semiaxes per "
                                f"particle) but the positions are {d}-dimensional")
    return shape


@dataclass(frozen=True, eq=False, init=False)
class Packing:
    """N particles in a d-dimensional cell (see the module docstring for conventions).

    ``Packing(positions, radii, lattice)`` is a sphere packing in a periodic cell;
    ``shape=`` (instead of ``radii``) gives other particle shapes and ``boundary=`` hard walls or
    a container.

    Construction validates everything and refuses bad input with :class:`InvalidInputError`.
    Overlaps (between particles, or of a particle with a wall) beyond ``overlap_tol`` are refused
    unless ``allow_overlap=True`` (e.g. for an intermediate SLP step or a deliberately overlapping
    test configuration). The arrays are stored read-only; engines work on copies.

    Parameters
    ----------
    positions : array_like, shape (N, d)
        Cartesian centres; N >= 1, d = 1..12.
    radii : array_like, shape (N,), optional
        Sphere radii (positive). Give either ``radii`` or ``shape``.
    lattice : array_like, shape (d, d)
        The cell: lattice vectors as columns; must be non-singular.
    species : array_like of int, shape (N,), optional
        An integer label per particle.
    boundary : "periodic", HardWalls or SphericalContainer, default "periodic"
        The boundary (:mod:`hardpack.geometry.boundaries`).
    allow_overlap : bool, default False
        Accept overlaps and wall crossings beyond ``overlap_tol``.
    overlap_tol : float, default 1e-9
        Relative overlap tolerance, 0 <= overlap_tol < 1 (module docstring).
    shape : Spheres or Ellipsoids, optional (keyword only)
        The particle shapes (:mod:`hardpack.geometry.shapes`), instead of ``radii``.

    Raises
    ------
    InvalidInputError
        If positions, radii, lattice or species have the wrong shape, type or non-finite entries;
        neither or both of radii and shape are given, or shape is not Spheres or Ellipsoids; d is
        outside 1..12; the lattice is missing or singular; the boundary is not one of the above or
        does not fit the lattice; overlap_tol is outside [0, 1); or, unless ``allow_overlap``,
        particles overlap or cross the boundary beyond ``overlap_tol``.
    """

    positions: np.ndarray
    shape: Spheres | Ellipsoids
    lattice: np.ndarray
    species: np.ndarray | None
    boundary: Periodic | HardWalls | SphericalContainer
    allow_overlap: bool
    overlap_tol: float

    def __init__(self, positions, radii=None, lattice=None, species=None, boundary="periodic",
                 allow_overlap: bool = False, overlap_tol: float = DEFAULT_OVERLAP_TOL, *, shape=None):
        pos = as_finite_array("positions", positions, "(N, d)")
        if pos.ndim != 2:
            raise InvalidInputError(
                f"positions must have shape (N, d), got an array of shape {pos.shape}; "
                "pass one row of d coordinates per particle"
            )
        n, d = pos.shape
        if n < 1:
            raise InvalidInputError("a packing needs at least one particle (positions has 0 rows)")
        if not MIN_DIM <= d <= MAX_DIM:
            raise InvalidInputError(
                f"dimension d = {d} is not supported; hardpack handles d = {MIN_DIM}..{MAX_DIM}"
            )
        shape = _particle_shape(radii, shape, n, d)
        if lattice is None:
            raise InvalidInputError("a packing needs a lattice: the d x d matrix whose columns are the "
                                    "lattice vectors (the cell)")
        lat = as_finite_array("lattice", lattice, "(d, d)")
        if lat.shape != (d, d):
            raise InvalidInputError(
                f"lattice must be a ({d}, {d}) matrix whose columns are the lattice vectors, "
                f"got shape {lat.shape}"
            )
        det = np.linalg.det(lat)
        scale = np.prod(np.linalg.norm(lat, axis=0))
        if not abs(det) > 1e-12 * scale:
            raise InvalidInputError(
                f"lattice is singular (det = {det:.3e}): its columns must be {d} linearly "
                "independent lattice vectors"
            )
        boundary = as_boundary(boundary)
        boundary.check(lat)
        if species is not None:
            species = np.array(species)
            if species.shape != (n,) or not np.issubdtype(species.dtype, np.integer):
                raise InvalidInputError(
                    f"species must be an integer array of shape ({n},), got dtype "
                    f"{species.dtype} and shape {species.shape}"
                )
            species = species.astype(np.int32)
        if not (0 <= overlap_tol < 1):
            raise InvalidInputError(f"overlap_tol must be in [0, 1), got {overlap_tol}")
        for name, arr in (("positions", pos), ("lattice", lat), ("species", species)):
            if arr is not None:
                arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "shape", shape)
        object.__setattr__(self, "boundary", boundary)
        object.__setattr__(self, "allow_overlap", bool(allow_overlap))
        object.__setattr__(self, "overlap_tol", overlap_tol)
        if not self.allow_overlap:
            self._refuse_overlaps()

    def _refuse_overlaps(self) -> None:
        walls = self.containment_report(self.overlap_tol)
        if walls.n_outside:
            raise InvalidInputError(
                f"particles cross the boundary beyond the tolerance {self.overlap_tol:g}: {walls}. "
                "Hard particles must stay inside their walls or container: move them in or shrink "
                "them; in Python, Packing(..., allow_overlap=True) accepts such a configuration"
            )
        report = self.overlap_report(self.overlap_tol)
        if report.n_overlapping:
            raise InvalidInputError(
                f"particles overlap beyond the tolerance {self.overlap_tol:g}: {report}. "
                "Hard particles must not overlap: regenerate the packing or shrink the radii "
                "(`hardpack info FILE` lists the overlaps); in Python, Packing(..., "
                "allow_overlap=True) accepts a deliberately overlapping configuration"
            )

    # ------------------------------------------------------------------ basic properties
    @property
    def n_particles(self) -> int:
        return self.positions.shape[0]

    @property
    def dim(self) -> int:
        return self.positions.shape[1]

    @property
    def radii(self) -> np.ndarray:
        """Sphere radii (N,); refused for other shapes (see ``shape``)."""
        if self.shape.kind != "sphere":
            raise InvalidInputError(
                f"this packing holds {self.shape.name}, which have no radii: use packing.shape "
                "(semiaxes, orientations), or packing.shape.bounding_radii for neighbour search"
            )
        return self.shape.radii

    @property
    def volume(self) -> float:
        """Volume of the region the particles fill: |det(lattice)| for a periodic cell or hard
        walls, V_d(R) for a spherical container."""
        return self.boundary.volume(self.lattice)

    @property
    def phi(self) -> float:
        """Volume fraction: the particles' volume (per shape) over :attr:`volume`."""
        return float(self.shape.volumes(self.dim).sum() / self.volume)

    @property
    def heights(self) -> np.ndarray:
        """Perpendicular widths of the cell: the distance between opposite faces, per lattice vector.

        h_k = 1 / |row k of lattice^-1|; a sphere of diameter D fits without touching its own
        image along direction k only if D < h_k.
        """
        return 1.0 / np.linalg.norm(np.linalg.inv(self.lattice), axis=1)

    @property
    def is_orthorhombic(self) -> bool:
        off = self.lattice - np.diag(np.diag(self.lattice))
        return bool(np.all(off == 0) and np.all(np.diag(self.lattice) > 0))

    def require_periodic_spheres(self, user: str) -> None:
        """Refuse this packing, naming ``user``, unless it is hard spheres in a periodic cell.

        That is the only model the simulation and analysis modules that call this handle so far.

        Parameters
        ----------
        user : str
            Who refuses, for the message (e.g. "the MD engine").

        Raises
        ------
        InvalidInputError
            If the particles are not spheres or the boundary is not periodic.
        """
        if self.shape.kind != "sphere":
            raise InvalidInputError(f"{self.shape.name} are not supported by {user} yet; it handles hard "
                                    "spheres only")
        if self.boundary.kind != "periodic":
            raise InvalidInputError(f"{self.boundary.name} are not supported by {user} yet; it handles "
                                    f"periodic cells only (this packing has {self.boundary})")

    # ------------------------------------------------------------------ coordinates
    def fractional(self) -> np.ndarray:
        """Fractional coordinates s = lattice^-1 x, wrapped into [0, 1) along the periodic axes
        (along walled axes they are as they stand: in [0, 1] for particles inside the walls)."""
        s = np.linalg.solve(self.lattice, self.positions.T).T
        if self.boundary.kind == "periodic":
            s -= np.floor(s)
            s[s >= 1.0] = 0.0  # floor can leave exactly 1.0 by round-off
        else:
            periodic = self.boundary.periodic_axes(self.dim)
            w = s[:, periodic]
            w -= np.floor(w)
            w[w >= 1.0] = 0.0
            s[:, periodic] = w
        return s

    def wrapped(self) -> "Packing":
        """The same packing with every centre inside the unit cell along the periodic axes
        (coordinates along walled axes are kept bit for bit: periodic lattice vectors have no
        component along them)."""
        positions = self.fractional() @ self.lattice.T
        if self.boundary.kind != "periodic":
            walled = ~self.boundary.periodic_axes(self.dim)
            positions[:, walled] = self.positions[:, walled]
        return self.replace(positions=positions)

    def replace(self, **changes) -> "Packing":
        """A validated copy with some fields replaced (e.g. positions, radii, shape, lattice)."""
        fields = dict(
            positions=self.positions, lattice=self.lattice, species=self.species,
            boundary=self.boundary, allow_overlap=self.allow_overlap, overlap_tol=self.overlap_tol,
        )
        if "radii" not in changes:
            fields["shape"] = self.shape
        elif self.shape.kind != "sphere" and "shape" not in changes:
            raise InvalidInputError(f"this packing holds {self.shape.name}: replace(radii=...) would make them "
                                    "spheres; pass shape=Spheres(radii) to do that on purpose")
        fields.update(changes)
        return Packing(**fields)

    def tiled(self, reps) -> "Packing":
        """The packing repeated ``reps`` times along each lattice vector.

        N prod(reps) particles in the cell with columns reps_k a_k, same phi and contacts. Only periodic
        axes can be repeated (reps 1 along walled axes).

        Parameters
        ----------
        reps : int or sequence of int, shape (d,)
            Positive repetitions per lattice vector.

        Returns
        -------
        Packing
            The tiled packing: copy t (t = 0..prod(reps) - 1, the translations in C order over
            the lattice vectors) of particle i is particle t N + i; shapes and species are repeated.

        Raises
        ------
        InvalidInputError
            If ``reps`` are not positive integers or exceed 1 along an axis without periodic images.
        """
        reps = np.broadcast_to(np.asarray(reps), (self.dim,))
        if not np.issubdtype(reps.dtype, np.integer) or (reps < 1).any():
            raise InvalidInputError(f"reps must be positive integers, one per lattice vector, got {reps.tolist()}")
        if (reps[~self.boundary.periodic_axes(self.dim)] > 1).any():
            raise InvalidInputError(f"reps must be 1 along the axes without periodic images ({self.boundary}), "
                                    f"got {reps.tolist()}")
        shifts = np.stack(np.meshgrid(*[np.arange(r) for r in reps], indexing="ij"), -1).reshape(-1, self.dim)
        offsets = shifts @ self.lattice.T  # (K, d) Cartesian translations
        k = len(shifts)
        return self.replace(
            positions=(self.positions[None, :, :] + offsets[:, None, :]).reshape(-1, self.dim),
            shape=self.shape.take(np.tile(np.arange(self.n_particles), k)), lattice=self.lattice * reps[None, :],
            species=None if self.species is None else np.tile(self.species, k),
        )

    def minimum_image(self, dx: np.ndarray) -> np.ndarray:
        """Reduce separation vectors by lattice vectors: s - round(s) in fractional space, along the
        periodic axes only.

        This is the exact minimum image for orthorhombic cells; for sheared cells it is the
        nearest image only when the cell is reasonably reduced. Use
        :func:`hardpack.geometry.neighbours.pairs_within` for an exact search with all images.

        Parameters
        ----------
        dx : array_like of float, shape (..., d)
            Cartesian separation vectors.

        Returns
        -------
        numpy.ndarray of float, shape (..., d)
            The reduced vectors.
        """
        dx = np.asarray(dx, dtype=float)
        s = np.linalg.solve(self.lattice, dx.reshape(-1, self.dim).T).T
        if self.boundary.kind == "periodic":
            s -= np.round(s)
        else:
            periodic = self.boundary.periodic_axes(self.dim)
            s[:, periodic] -= np.round(s[:, periodic])
        return (s @ self.lattice.T).reshape(dx.shape)

    def separation(self, i: int, j: int) -> np.ndarray:
        """Minimum-image separation vector x_j - x_i (:meth:`minimum_image`).

        Parameters
        ----------
        i, j : int
            Particle indices.

        Returns
        -------
        numpy.ndarray of float, shape (d,)
            x_j - x_i reduced by lattice vectors along the periodic axes.
        """
        return self.minimum_image(self.positions[j] - self.positions[i])

    # ------------------------------------------------------------------ overlaps
    def overlap_report(self, tol: float = DEFAULT_OVERLAP_TOL) -> OverlapReport:
        """Count pairs with relative overlap 1 - mu > tol, with every periodic image.

        Spheres: mu = distance / (r_i + r_j). Ellipsoids: mu = sqrt(zeta + 1) of the Perram-Wertheim
        potential (module docstring) of the pairs whose bounding spheres overlap. The worst pair
        (largest relative overlap) is named even when it is within tolerance, so callers can report
        how close the packing is to touching.

        Parameters
        ----------
        tol : float, default DEFAULT_OVERLAP_TOL
            Relative tolerance.

        Returns
        -------
        OverlapReport
            Number of overlapping pairs and the worst pair (-1 and overlap -inf when no pair is in
            contact range).
        """
        from hardpack.geometry.neighbours import pairs_within

        if self.shape.kind == "sphere":
            pairs = pairs_within(self, rel_gap=0.0)  # images along periodic axes only
            rel = 1.0 - pairs.distance / pairs.contact
        else:
            from hardpack.geometry.ellipsoid_pairs import potential_pairs

            near = potential_pairs(self, rel_gap=0.0)
            pairs, rel = near.pairs, 1.0 - near.mu
        if len(pairs.i) == 0:
            return OverlapReport(0, -1, -1, (), float("-inf"))
        k = int(np.argmax(rel))
        return OverlapReport(
            n_overlapping=int((rel > tol).sum()),
            worst_i=int(pairs.i[k]),
            worst_j=int(pairs.j[k]),
            shift=tuple(int(v) for v in pairs.shift[k]),
            overlap=float(rel[k]),
        )

    def containment_report(self, tol: float = DEFAULT_OVERLAP_TOL) -> ContainmentReport:
        """Count particles crossing a hard wall or the container by more than ``tol`` of their
        radius (see :mod:`hardpack.geometry.boundaries`); the worst particle is named.

        Ellipsoids: against hard walls, by their extent along each wall normal; in a spherical
        container, by the exact gap h = R - rho to the farthest surface point
        (:mod:`hardpack.geometry.ellipsoid_container`), as the relative overlap -h / a_max (the
        sphere's 1 - (R - |x - c|) / r for equal semiaxes).

        Parameters
        ----------
        tol : float, default DEFAULT_OVERLAP_TOL
            Relative tolerance.

        Returns
        -------
        ContainmentReport
            Particles outside beyond ``tol`` and the worst one; no particle named in a periodic cell.
        """
        if self.shape.kind == "sphere":
            return self.boundary.containment(self.positions, self.shape.radii, self.lattice, tol)
        if self.boundary.kind == "hard_walls":
            from hardpack.geometry.contact import inverse_shapes

            inv = inverse_shapes(self.shape.semiaxes, self.shape.orientations.reshape(self.n_particles, -1))
            extents = np.sqrt(np.einsum("nkk->nk", inv))  # sqrt(e_k^T X^-1 e_k), Donev 2006, Sec. 2.2.5.1
            return self.boundary.containment(self.positions, extents, self.lattice, tol)
        if self.boundary.kind == "periodic":
            return self.boundary.containment(self.positions, self.shape.bounding_radii, self.lattice, tol)
        from hardpack.geometry.ellipsoid_container import container_gaps

        gap, _ = container_gaps(self.positions, self.shape, self.boundary.centre, self.boundary.radius)
        overlap = -gap / self.shape.bounding_radii
        i = int(np.argmax(overlap))
        return ContainmentReport(int((overlap > tol).sum()), i, "the container wall", float(overlap[i]))

    def __repr__(self) -> str:
        if self.shape.kind == "sphere":
            sizes = f"radii=[{self.radii.min():.4g}, {self.radii.max():.4g}]"
        else:
            sizes = f"{self.shape.kind}s, semiaxes=[{self.shape.semiaxes.min():.4g}, {self.shape.semiaxes.max():.4g}]"
        return (f"Packing(N={self.n_particles}, d={self.dim}, phi={self.phi:.6f}, {sizes}, "
                f"boundary={str(self.boundary)!r})")
