"""The packing model: N hard spheres in d dimensions in a periodic cell.

Conventions (used everywhere in hardpack):

- ``positions`` are Cartesian, shape (N, d).
- ``lattice`` is the d x d matrix whose **columns** are the lattice vectors (Donev's Lambda,
  dissertation ch. 3.2.2.1): a point with fractional coordinates s has Cartesian position
  x = lattice @ s, and the periodic images of x are x + lattice @ n for integer vectors n.
  A general (sheared) lattice is allowed, so strict-jamming tests and SLP can deform the cell.
- ``radii`` are the sphere radii, shape (N,).
- ``species`` is an optional integer label per particle (e.g. large/small of a binary mixture).
- ``boundary`` is "periodic" (the only one implemented so far; hard-wall containers will add
  "hardwall"). ``orientations`` is reserved for ellipsoids and must be None for spheres.

Overlap tolerance: two spheres overlap when their distance is below (r_i + r_j)(1 - tol). The
default relative tolerance ``DEFAULT_OVERLAP_TOL = 1e-9`` is far above double-precision round-off
after a collision (~1e-14) and far below any physical gap that matters (LS packings at reduced
pressure 1e12 have relative gaps of ~1e-12 that round-off may turn into overlaps of ~1e-14).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume

DEFAULT_OVERLAP_TOL = 1e-9
MIN_DIM, MAX_DIM = 1, 12
BOUNDARIES = ("periodic",)


@dataclass(frozen=True)
class OverlapReport:
    """Result of an overlap check: the worst pair and its relative overlap.

    ``overlap`` = 1 - distance / (r_i + r_j) of the worst pair (positive means overlapping);
    ``shift`` is the lattice image n with the separation x_j + lattice @ n - x_i.
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


def _as_float_array(name: str, value, shape_hint: str) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be numeric with shape {shape_hint}: {exc}") from None
    bad = ~np.isfinite(arr)
    if bad.any():
        where = np.argwhere(bad)[0].tolist()
        raise InvalidInputError(
            f"{name} contains a non-finite value (NaN or inf) at index {where}; "
            "every entry must be a finite number"
        )
    return arr


@dataclass(frozen=True, eq=False)
class Packing:
    """N spheres in a d-dimensional periodic cell (see the module docstring for conventions).

    Construction validates everything and refuses bad input with :class:`InvalidInputError`.
    Overlaps beyond ``overlap_tol`` are refused unless ``allow_overlap=True`` (e.g. for an
    intermediate SLP step or a deliberately overlapping test configuration).
    The arrays are stored read-only; engines work on copies.
    """

    positions: np.ndarray
    radii: np.ndarray
    lattice: np.ndarray
    species: np.ndarray | None = None
    boundary: str = "periodic"
    orientations: np.ndarray | None = None
    allow_overlap: bool = field(default=False, repr=False)
    overlap_tol: float = field(default=DEFAULT_OVERLAP_TOL, repr=False)

    def __post_init__(self):
        pos = _as_float_array("positions", self.positions, "(N, d)")
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
        radii = _as_float_array("radii", self.radii, "(N,)")
        if radii.shape != (n,):
            raise InvalidInputError(
                f"radii must have shape ({n},) to match {n} positions, got shape {radii.shape}"
            )
        if (radii <= 0).any():
            i = int(np.argmin(radii))
            raise InvalidInputError(
                f"radii must be positive; particle {i} has radius {float(radii[i])!r}"
            )
        lat = _as_float_array("lattice", self.lattice, "(d, d)")
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
        if self.boundary not in BOUNDARIES:
            raise InvalidInputError(
                f"boundary {self.boundary!r} is not supported; choose one of {BOUNDARIES}"
            )
        if self.orientations is not None:
            raise InvalidInputError(
                "orientations are reserved for ellipsoids, which are not implemented yet; "
                "pass orientations=None for spheres"
            )
        species = self.species
        if species is not None:
            species = np.array(species)
            if species.shape != (n,) or not np.issubdtype(species.dtype, np.integer):
                raise InvalidInputError(
                    f"species must be an integer array of shape ({n},), got dtype "
                    f"{species.dtype} and shape {species.shape}"
                )
            species = species.astype(np.int32)
        if not (0 <= self.overlap_tol < 1):
            raise InvalidInputError(f"overlap_tol must be in [0, 1), got {self.overlap_tol}")
        for name, arr in (("positions", pos), ("radii", radii), ("lattice", lat), ("species", species)):
            if arr is not None:
                arr.setflags(write=False)
                object.__setattr__(self, name, arr)
        if not self.allow_overlap:
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
    def volume(self) -> float:
        """Cell volume |det(lattice)|."""
        return float(abs(np.linalg.det(self.lattice)))

    @property
    def phi(self) -> float:
        """Volume fraction sum_i V_d(r_i) / |det lattice|."""
        return float(ball_volume(self.radii, self.dim).sum() / self.volume)

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

    # ------------------------------------------------------------------ coordinates
    def fractional(self) -> np.ndarray:
        """Fractional coordinates s = lattice^-1 x, wrapped into [0, 1)."""
        s = np.linalg.solve(self.lattice, self.positions.T).T
        s -= np.floor(s)
        s[s >= 1.0] = 0.0  # floor can leave exactly 1.0 by round-off
        return s

    def wrapped(self) -> "Packing":
        """The same packing with every centre inside the unit cell."""
        return self.replace(positions=self.fractional() @ self.lattice.T)

    def replace(self, **changes) -> "Packing":
        """A validated copy with some fields replaced (e.g. positions, radii, lattice)."""
        fields = dict(
            positions=self.positions, radii=self.radii, lattice=self.lattice,
            species=self.species, boundary=self.boundary, orientations=self.orientations,
            allow_overlap=self.allow_overlap, overlap_tol=self.overlap_tol,
        )
        fields.update(changes)
        return Packing(**fields)

    def tiled(self, reps) -> "Packing":
        """The periodic packing repeated ``reps`` times along each lattice vector (int or d ints):
        N prod(reps) particles in the cell with columns reps_k * a_k, same phi and contacts."""
        reps = np.broadcast_to(np.asarray(reps), (self.dim,))
        if not np.issubdtype(reps.dtype, np.integer) or (reps < 1).any():
            raise InvalidInputError(f"reps must be positive integers, one per lattice vector, got {reps.tolist()}")
        shifts = np.stack(np.meshgrid(*[np.arange(r) for r in reps], indexing="ij"), -1).reshape(-1, self.dim)
        offsets = shifts @ self.lattice.T  # (K, d) Cartesian translations
        k = len(shifts)
        return self.replace(
            positions=(self.positions[None, :, :] + offsets[:, None, :]).reshape(-1, self.dim),
            radii=np.tile(self.radii, k), lattice=self.lattice * reps[None, :],
            species=None if self.species is None else np.tile(self.species, k),
            orientations=None if self.orientations is None else np.concatenate([self.orientations] * k),
        )

    def minimum_image(self, dx: np.ndarray) -> np.ndarray:
        """Reduce separation vectors (..., d) by lattice vectors: s - round(s) in fractional space.

        This is the exact minimum image for orthorhombic cells; for sheared cells it is the
        nearest image only when the cell is reasonably reduced. Use
        :func:`hardpack.geometry.neighbours.pairs_within` for an exact search with all images.
        """
        dx = np.asarray(dx, dtype=float)
        s = np.linalg.solve(self.lattice, dx.reshape(-1, self.dim).T).T
        s -= np.round(s)
        return (s @ self.lattice.T).reshape(dx.shape)

    def separation(self, i: int, j: int) -> np.ndarray:
        """Minimum-image separation vector x_j - x_i."""
        return self.minimum_image(self.positions[j] - self.positions[i])

    # ------------------------------------------------------------------ overlaps
    def overlap_report(self, tol: float = DEFAULT_OVERLAP_TOL) -> OverlapReport:
        """Count pairs with distance < (r_i + r_j)(1 - tol), with all periodic images.

        The worst pair (largest relative overlap 1 - dist/(r_i + r_j)) is named even when it
        is within tolerance, so callers can report how close the packing is to touching.
        """
        from hardpack.geometry.neighbours import pairs_within

        pairs = pairs_within(self, rel_gap=0.0)
        if len(pairs.i) == 0:
            return OverlapReport(0, -1, -1, (), float("-inf"))
        rel = 1.0 - pairs.distance / pairs.contact
        k = int(np.argmax(rel))
        return OverlapReport(
            n_overlapping=int((rel > tol).sum()),
            worst_i=int(pairs.i[k]),
            worst_j=int(pairs.j[k]),
            shift=tuple(int(v) for v in pairs.shift[k]),
            overlap=float(rel[k]),
        )

    def __repr__(self) -> str:
        return (
            f"Packing(N={self.n_particles}, d={self.dim}, phi={self.phi:.6f}, "
            f"radii=[{self.radii.min():.4g}, {self.radii.max():.4g}], boundary={self.boundary!r})"
        )
