"""Boundaries of a packing: a periodic cell, hard walls on some axes, or a spherical container.

The lattice (d x d, columns = lattice vectors) is always there; the boundary says what its faces
are (Donev 2006, Sec. 3.2.2.1: each dimension of the unit cell is periodic or a hard wall;
Ch. 7: a spherical container inside a box that only serves the cell lists).

- :class:`Periodic`: every lattice vector is a period (the only boundary before format 2).
- :class:`HardWalls`: hard planar walls at x_k = 0 and x_k = L_k for each walled axis k, periodic
  along the other lattice vectors (a slit for one walled axis in 3D, a channel for two, a closed
  box for all). The lattice must be orthorhombic along the walled axes: lattice vector k is
  L_k e_k and no other lattice vector has a component along e_k. The periodic vectors may be
  sheared among themselves.
- :class:`SphericalContainer`: a hard spherical wall of radius R about ``centre``; no axis is
  periodic. The lattice must be an orthorhombic box [0, L_1] x ... x [0, L_d] that holds the
  container; it is a pseudo-boundary for cell lists (Donev 2006, Ch. 7) and plays no part in
  the physics: the volume fraction is over the container, V_d(R).

A particle and a wall are checked like a pair: the relative overlap of a sphere of radius r whose
centre is at distance h from a flat wall (or whose centre is at distance |x - c| from the centre
of a container of radius R, h = R - |x - c|) is 1 - h / r, positive when it crosses the wall.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.shapes import as_finite_array


@dataclass(frozen=True)
class ContainmentReport:
    """Result of a wall check: how many particles cross a wall and the worst one.

    ``overlap`` = 1 - h / r of the worst particle (positive means it crosses ``wall``); ``worst``
    is -1 when no particle is named (a periodic cell has no walls; ``wall`` then says why).

    Parameters
    ----------
    n_outside : int
        Particles whose relative overlap with a wall exceeds the tolerance.
    worst : int
        Index of the particle with the largest relative overlap, or -1.
    wall : str
        The wall of the worst particle, in words (or why there is none).
    overlap : float
        1 - h / r of the worst particle (-inf without walls).
    """

    n_outside: int
    worst: int
    wall: str
    overlap: float

    def __str__(self) -> str:
        if self.worst < 0:
            return self.wall
        if self.overlap <= 0:
            return (f"no particle crosses a wall; closest: particle {self.worst}, at a gap of "
                    f"{-self.overlap:.3e} of its radius from {self.wall}")
        head = (f"{self.n_outside} particle(s) cross a wall" if self.n_outside
                else "no particle crosses a wall beyond the tolerance")
        return f"{head}; worst: particle {self.worst} crosses {self.wall} by {self.overlap:.3e} of its radius"


@dataclass(frozen=True)
class WallContacts:
    """Particle-wall contacts within a relative gap: particle ``particle[m]`` is at relative gap
    ``gap[m]`` = h / r - 1 (h: centre-wall distance, r: radius) from a wall whose outward unit
    normal at the contact point is ``normal[m]`` (the wall pushes the particle along -normal).

    Parameters
    ----------
    particle : numpy.ndarray of int, shape (M,)
    normal : numpy.ndarray of float, shape (M, d)
    gap : numpy.ndarray of float, shape (M,)
    """

    particle: np.ndarray
    normal: np.ndarray
    gap: np.ndarray

    def __len__(self) -> int:
        return len(self.particle)


def _wall_contacts(h: np.ndarray, normals: np.ndarray, radii: np.ndarray, rel_gap: float) -> WallContacts:
    """Contacts from the centre-wall distances h (N, W) and outward normals (N, W, d) of W walls."""
    gap = h / radii[:, None] - 1.0
    i, w = np.nonzero(gap <= rel_gap)
    return WallContacts(i.astype(np.int64), normals[i, w], gap[i, w])


def _no_walls() -> ContainmentReport:
    return ContainmentReport(0, -1, "no walls", float("-inf"))


def _report(overlap: np.ndarray, wall_of, tol: float) -> ContainmentReport:
    """Report of the relative overlaps (N,) of the particles with their nearest walls; ``wall_of(i)``
    names the wall of particle i."""
    i = int(np.argmax(overlap))
    return ContainmentReport(int((overlap > tol).sum()), i, wall_of(i), float(overlap[i]))


class Boundary:
    """What a packing's boundary answers (:class:`Periodic`, :class:`HardWalls`,
    :class:`SphericalContainer`); each method is documented here once."""

    kind: ClassVar[str]
    name: ClassVar[str]

    def check(self, lattice: np.ndarray) -> None:
        """Refuse a lattice that does not suit the boundary.

        Parameters
        ----------
        lattice : numpy.ndarray of float, shape (d, d)
            The packing's lattice, columns = lattice vectors.

        Raises
        ------
        InvalidInputError
            If the boundary cannot hold a cell of this lattice.
        """
        raise NotImplementedError

    def periodic_axes(self, d: int) -> np.ndarray:
        """Which lattice vectors are periods.

        Parameters
        ----------
        d : int
            Dimension.

        Returns
        -------
        numpy.ndarray of bool, shape (d,)
            True for the lattice vectors that are periods (axes with periodic images).
        """
        raise NotImplementedError

    def volume(self, lattice: np.ndarray) -> float:
        """Volume of the region the particles fill.

        Parameters
        ----------
        lattice : numpy.ndarray of float, shape (d, d)
            The packing's lattice, columns = lattice vectors.

        Returns
        -------
        float
        """
        raise NotImplementedError

    def containment(self, positions, radii, lattice, tol: float) -> ContainmentReport:
        """Relative overlap of every particle with its worst wall.

        Parameters
        ----------
        positions : numpy.ndarray of float, shape (N, d)
            Cartesian centres.
        radii : numpy.ndarray of float, shape (N,)
            Particle radii.
        lattice : numpy.ndarray of float, shape (d, d)
            The packing's lattice (checked by :meth:`check`).
        tol : float
            Relative tolerance: a particle crosses a wall when its relative overlap exceeds it.

        Returns
        -------
        ContainmentReport
            The particles outside and the worst one (n_outside = 0, worst = -1 without walls).
        """
        raise NotImplementedError

    def wall_contacts(self, positions, radii, lattice, rel_gap: float) -> WallContacts:
        """Particle-wall contacts within a relative gap.

        Parameters
        ----------
        positions : numpy.ndarray of float, shape (N, d)
            Cartesian centres.
        radii : numpy.ndarray of float, shape (N,)
            Sphere radii.
        lattice : numpy.ndarray of float, shape (d, d)
            The packing's lattice (checked by :meth:`check`).
        rel_gap : float
            Largest relative gap h / r - 1 of a contact.

        Returns
        -------
        WallContacts
            The contacts: particle, outward wall normal, relative gap (M = 0 without walls).
        """
        raise NotImplementedError


@dataclass(frozen=True)
class Periodic(Boundary):
    """A periodic cell: every lattice vector is a period."""

    kind: ClassVar[str] = "periodic"
    name: ClassVar[str] = "periodic cells"

    def check(self, lattice: np.ndarray) -> None:
        """Refuse a lattice that does not suit the boundary: every lattice suits a periodic cell.

        The packing checks separately that the lattice is non-singular; :meth:`HardWalls.check` and
        :meth:`SphericalContainer.check` raise InvalidInputError for lattices they do not suit.

        See :meth:`Boundary.check` for the parameters and the return value.
        """

    def periodic_axes(self, d: int) -> np.ndarray:
        """Which lattice vectors are periods: all of them.

        See :meth:`Boundary.periodic_axes` for the parameters and the return value.
        """
        return np.ones(d, dtype=bool)

    def volume(self, lattice: np.ndarray) -> float:
        """Volume of the region the particles fill: the cell, |det(lattice)|.

        See :meth:`Boundary.volume` for the parameters and the return value.
        """
        return float(abs(np.linalg.det(lattice)))

    def containment(self, positions, radii, lattice, tol: float) -> ContainmentReport:
        """Relative overlap 1 - h / r of every particle with its worst wall; a periodic cell has none.

        See :meth:`Boundary.containment` for the parameters and the return value.
        """
        return _no_walls()

    def wall_contacts(self, positions, radii, lattice, rel_gap: float) -> WallContacts:
        """Particle-wall contacts within relative gap ``rel_gap``; a periodic cell has no walls, so none.

        See :meth:`Boundary.wall_contacts` for the parameters and the return value.
        """
        d = positions.shape[1]
        return WallContacts(np.zeros(0, np.int64), np.zeros((0, d)), np.zeros(0))

    def __str__(self) -> str:
        return "periodic"


@dataclass(frozen=True)
class HardWalls(Boundary):
    """Hard walls at x_k = 0 and x_k = L_k for every axis k in ``axes``; periodic along the others.

    Parameters
    ----------
    axes : int or sequence of int
        The distinct walled axes (0 = x, 1 = y, ...); stored sorted as a tuple. The packing's
        lattice must be orthorhombic along them (:meth:`check`).

    Raises
    ------
    InvalidInputError
        If ``axes`` is empty, not integers, negative or repeated.
    """

    axes: tuple
    kind: ClassVar[str] = "hard_walls"
    name: ClassVar[str] = "hard walls"

    def __post_init__(self):
        axes = np.atleast_1d(np.asarray(self.axes))
        if axes.size == 0:
            raise InvalidInputError("hard walls need at least one walled axis; a cell without walls "
                                    "is boundary='periodic'")
        if axes.ndim != 1 or axes.dtype.kind not in "iu" or (axes < 0).any() or len(set(axes.tolist())) != axes.size:
            raise InvalidInputError(
                f"hard-wall axes must be distinct non-negative axis numbers (0 = x, 1 = y, ...), "
                f"got {self.axes!r}"
            )
        axes = sorted(int(k) for k in axes)
        object.__setattr__(self, "axes", tuple(axes))

    def check(self, lattice: np.ndarray) -> None:
        """Refuse a lattice that is not orthorhombic along the walled axes.

        Lattice vector k must be L_k e_k with L_k > 0 and no other lattice vector may have a
        component along e_k, for every walled axis k.

        See :meth:`Boundary.check` for the parameters and the return value.

        Raises
        ------
        InvalidInputError
            If a walled axis is >= d or the lattice is not orthorhombic along it.
        """
        d = lattice.shape[0]
        if self.axes[-1] >= d:
            raise InvalidInputError(f"hard-wall axis {self.axes[-1]} does not exist in {d} dimensions "
                                    f"(axes are 0..{d - 1})")
        for k in self.axes:
            others = np.delete(np.arange(d), k)
            if not (lattice[k, k] > 0 and np.all(lattice[others, k] == 0) and np.all(lattice[k, others] == 0)):
                raise InvalidInputError(
                    f"with hard walls on axis {k} the lattice must be orthorhombic along it: lattice "
                    f"vector {k} (column {k}) must be L e_{k} with L > 0 and no other lattice vector may "
                    f"have a component along e_{k} (row {k} zero off the diagonal); got column "
                    f"{lattice[:, k].tolist()} and row {lattice[k].tolist()}"
                )

    def periodic_axes(self, d: int) -> np.ndarray:
        """Which lattice vectors are periods: all but the walled axes.

        See :meth:`Boundary.periodic_axes` for the parameters and the return value.
        """
        mask = np.ones(d, dtype=bool)
        mask[list(self.axes)] = False
        return mask

    def volume(self, lattice: np.ndarray) -> float:
        """Volume of the region the particles fill: the cell between the walls, |det(lattice)|.

        See :meth:`Boundary.volume` for the parameters and the return value.
        """
        return float(abs(np.linalg.det(lattice)))

    def containment(self, positions, radii, lattice, tol: float) -> ContainmentReport:
        """Relative overlap 1 - h / r of every particle with its worst wall.

        h is the centre-wall distance x_k (wall at 0) or L_k - x_k (wall at L_k, L_k the diagonal
        entry of the lattice), from the positions as given (not wrapped).

        See :meth:`Boundary.containment` for the parameters and the return value. Here ``radii`` may
        also have shape (N, d): each particle's extent along each axis (e.g. of an ellipsoid), of which
        the walled axes are used.
        """
        axes = list(self.axes)
        x = positions[:, axes]
        length = np.diag(lattice)[axes]
        h = np.concatenate([x, length - x], axis=1)  # distance to the wall at 0, then at L, per axis
        reach = radii[:, None] if radii.ndim == 1 else np.tile(radii[:, axes], 2)
        rel = 1.0 - h / reach
        nearest = np.argmax(rel, axis=1)
        overlap = rel[np.arange(len(h)), nearest]
        names = [f"the wall x_{k} = 0" for k in axes] + [f"the wall x_{k} = {v:.6g}" for k, v in zip(axes, length)]
        return _report(overlap, lambda i: names[nearest[i]], tol)

    def wall_contacts(self, positions, radii, lattice, rel_gap: float) -> WallContacts:
        """Every sphere within relative gap ``rel_gap`` of a wall (a sphere may touch several);
        normals -e_k at x_k = 0 and +e_k at x_k = L_k.

        See :meth:`Boundary.wall_contacts` for the parameters and the return value.
        """
        n, d = positions.shape
        axes = list(self.axes)
        length = np.diag(lattice)[axes]
        h = np.concatenate([positions[:, axes], length - positions[:, axes]], axis=1)
        normals = np.zeros((2 * len(axes), d))
        normals[np.arange(len(axes)), axes] = -1.0
        normals[len(axes) + np.arange(len(axes)), axes] = 1.0
        return _wall_contacts(h, np.broadcast_to(normals, (n,) + normals.shape), radii, rel_gap)

    def __str__(self) -> str:
        return f"hard walls on axes {list(self.axes)}"


@dataclass(frozen=True)
class SphericalContainer(Boundary):
    """A hard spherical wall of ``radius`` about ``centre``, inside the orthorhombic lattice box.

    Parameters
    ----------
    centre : sequence of float, shape (d,)
        Centre of the container, in the coordinates of the packing.
    radius : float
        Radius R > 0 of the container; the volume fraction is over V_d(R).

    Raises
    ------
    InvalidInputError
        If ``centre`` is not d finite numbers or ``radius`` is not one positive finite number.
        The fit into the packing's lattice box is checked by :meth:`check`.
    """

    centre: tuple
    radius: float
    kind: ClassVar[str] = "spherical_container"
    name: ClassVar[str] = "spherical containers"

    def __post_init__(self):
        centre = as_finite_array("container centre", self.centre, "(d,)")
        radius = as_finite_array("container radius", self.radius, "()")
        if centre.ndim != 1 or radius.ndim != 0:
            raise InvalidInputError(f"a spherical container needs a centre of d coordinates and one radius, "
                                    f"got centre of shape {centre.shape} and radius of shape {radius.shape}")
        if not radius > 0:
            raise InvalidInputError(f"the container radius must be positive, got {float(radius)!r}")
        object.__setattr__(self, "centre", tuple(float(v) for v in centre))
        object.__setattr__(self, "radius", float(radius))

    def check(self, lattice: np.ndarray) -> None:
        """Refuse a lattice that is not an orthorhombic box [0, L_1] x ... x [0, L_d] holding the container.

        See :meth:`Boundary.check` for the parameters and the return value.

        Raises
        ------
        InvalidInputError
            If the centre does not have d coordinates, the lattice is not diagonal with positive
            entries, or the container does not lie inside the box.
        """
        d = lattice.shape[0]
        if len(self.centre) != d:
            raise InvalidInputError(f"the container centre has {len(self.centre)} coordinates; the packing "
                                    f"is {d}-dimensional")
        box = np.diag(lattice)
        if not (np.all(lattice == np.diag(box)) and np.all(box > 0)):
            raise InvalidInputError(
                "a spherical container sits in an orthorhombic box (a diagonal lattice with positive "
                f"entries, used for cell lists); got lattice {lattice.tolist()}"
            )
        c = np.array(self.centre)
        if np.any(c - self.radius < 0) or np.any(c + self.radius > box):
            raise InvalidInputError(
                f"the container (centre {list(self.centre)}, radius {self.radius:g}) must lie inside the "
                f"box [0, L_k] of the lattice, L = {box.tolist()}; enlarge the box or move the centre"
            )

    def periodic_axes(self, d: int) -> np.ndarray:
        """Which lattice vectors are periods: none.

        See :meth:`Boundary.periodic_axes` for the parameters and the return value.
        """
        return np.zeros(d, dtype=bool)

    def volume(self, lattice: np.ndarray) -> float:
        """The container's volume V_d(R) (the box is only a pseudo-boundary).

        See :meth:`Boundary.volume` for the parameters and the return value.
        """
        return float(ball_volume(self.radius, lattice.shape[0]))

    def containment(self, positions, radii, lattice, tol: float) -> ContainmentReport:
        """Relative overlap 1 - (R - |x - c|) / r of every sphere with the container wall.

        See :meth:`Boundary.containment` for the parameters and the return value.
        """
        dx = positions - np.array(self.centre)
        h = self.radius - np.sqrt(np.einsum("ij,ij->i", dx, dx))
        return _report(1.0 - h / radii, lambda i: "the container wall", tol)

    def wall_contacts(self, positions, radii, lattice, rel_gap: float) -> WallContacts:
        """Every sphere within relative gap ``rel_gap`` of the container wall; normal (x - c) / |x - c|
        (a sphere at the centre can touch only a container of its own size and gets normal e_0).

        See :meth:`Boundary.wall_contacts` for the parameters and the return value.
        """
        dx = positions - np.array(self.centre)
        dist = np.sqrt(np.einsum("ij,ij->i", dx, dx))
        normal = np.zeros_like(dx)
        normal[:, 0] = 1.0
        moved = dist > 0
        normal[moved] = dx[moved] / dist[moved, None]
        return _wall_contacts((self.radius - dist)[:, None], normal[:, None, :], radii, rel_gap)

    def __str__(self) -> str:
        return f"spherical container (centre {list(self.centre)}, radius {self.radius:.6g})"


BOUNDARY_KINDS = ("periodic", "hard_walls", "spherical_container")


def as_boundary(value):
    """A boundary object from ``value``: one of the classes above, or the string ``"periodic"``.

    Parameters
    ----------
    value : Periodic, HardWalls, SphericalContainer or str
        The boundary, or "periodic".

    Returns
    -------
    Periodic, HardWalls or SphericalContainer
        The boundary object.

    Raises
    ------
    InvalidInputError
        For anything else.
    """
    if isinstance(value, (Periodic, HardWalls, SphericalContainer)):
        return value
    if isinstance(value, str) and value == "periodic":
        return PERIODIC
    raise InvalidInputError(
        f"boundary {value!r} is not supported; pass 'periodic', HardWalls(axes) or "
        "SphericalContainer(centre, radius) (hardpack.geometry.boundaries)"
    )


PERIODIC = Periodic()
