"""Contact network of a sphere packing from a gap tolerance delta: pairs and hard-wall contacts.

A pair {i, j} (any periodic image n, including a particle's own image in small cells) is a
potential contact when ``|r_ij| <= (1 + delta) D_ij`` with ``D_ij = r_i + r_j``
(Donev 2006, dissertation Eq. 4.5, written there for monodisperse D; the polydisperse
D_ij = (D_i + D_j)/2 is the one of sec. 4.5.1.1). Periodic images follow sec. 4.4.3:
a contact between i and the image of j shifted by ``lattice @ n`` is stored as (i, j, n).

Convention used throughout :mod:`hardpack.jamming`: positions are the packing's *wrapped*
centres ``x`` (inside the unit cell, as :func:`pairs_within` uses them), the separation is
``r_ij = x_j + lattice @ n - x_i`` (from i to j) and the unit normal ``u_ij = r_ij / |r_ij|``.
The gap ``h_ij = |r_ij| - D_ij`` is absolute; overlaps inside the packing's overlap tolerance
(|h| <= 1e-9 D) are clipped to h = 0, i.e. treated as exact contacts.

Hard walls and spherical containers (Donev 2006, sec. 4.4.3: "we add a potential contact to the
contact network from each sphere close to a wall to the closest point on the wall, and fix the
endpoint on the wall"): a sphere i whose centre is at distance h from a wall with
``h <= (1 + delta) r_i`` has a wall contact, stored as a contact (i, j = i, n = 0) with
``wall`` >= 0 naming the wall (-1 for a pair), separation ``h n`` (n the wall's outward unit
normal: from the centre to the closest point on the wall), contact distance r_i and gap
h - r_i. Its endpoint is fixed, so its column of the rigidity matrix has the particle part of i
only: the linearised constraint is n . dr_i <= h - r_i. A wall contact counts once in the
contact numbers. Walls are numbered 2 k (the wall x_k = 0) and 2 k + 1 (x_k = L_k) for the
walled axes k of :class:`hardpack.geometry.boundaries.HardWalls`, 0 for the wall of a
:class:`hardpack.geometry.boundaries.SphericalContainer`.

Trivial motions (moved out of the tests by :func:`hardpack.jamming.rigidity.gauge_dofs`): the
translations along the periodic axes, and for a spherical container (which has no periodic axis)
the d(d - 1)/2 rotations about its centre. Hard walls along every axis leave none (Donev 2006,
sec. 4.4.2: "hard-wall containers do not allow any trivial unjamming motions").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours import pairs_within, wrapped_positions
from hardpack.geometry.packing import Packing


def check_delta(delta) -> float:
    """Validate the relative gap tolerance: a finite number with 0 < delta < 1.

    Parameters
    ----------
    delta : object
        The tolerance as given (converted with ``float``).

    Returns
    -------
    float
        The tolerance.

    Raises
    ------
    InvalidInputError
        If it is not a number in (0, 1).
    """
    try:
        value = float(delta)
    except (TypeError, ValueError):
        raise InvalidInputError(f"delta must be a number, got {delta!r}") from None
    if not np.isfinite(value) or not 0.0 < value < 1.0:
        raise InvalidInputError(
            f"delta = {delta!r} is not a valid gap tolerance: it is the relative surface gap "
            "below which two spheres count as touching and must satisfy 0 < delta < 1 "
            "(typical: 1e-6..1e-3 for LS packings at high pressure, 0.01..0.5 for the "
            "sequential-loading test)"
        )
    return value


class ContactArrays:
    """What the contact networks of spheres and of ellipsoids share: contacts (``i``, ``j``) of the
    particles at ``positions`` (N, d); ``wall`` (M,) is -1 for a pair and the wall's number for a
    wall contact (None in the constructor: pairs only)."""

    def __post_init__(self):
        if self.wall is None:
            object.__setattr__(self, "wall", np.full(len(self.i), -1, dtype=np.int64))

    @property
    def is_wall(self) -> np.ndarray:
        """(M,) True for the wall contacts."""
        return self.wall >= 0

    @property
    def n_wall_contacts(self) -> int:
        """Number of wall contacts."""
        return int(np.count_nonzero(self.is_wall))

    @property
    def n_contacts(self) -> int:
        return len(self.i)

    @property
    def n_particles(self) -> int:
        return self.positions.shape[0]

    @property
    def dim(self) -> int:
        return self.positions.shape[1]

    def among(self, active: np.ndarray | None) -> np.ndarray:
        """Boolean mask of contacts whose both ends are ``active`` (all if None).

        Parameters
        ----------
        active : numpy.ndarray of bool, shape (N,), or None
            The particles kept.

        Returns
        -------
        numpy.ndarray of bool, shape (M,)
            True for the contacts between two active particles (a wall contact: its particle active).
        """
        if active is None:
            return np.ones(self.n_contacts, dtype=bool)
        return active[self.i] & active[self.j]

    def counts(self, active: np.ndarray | None = None) -> np.ndarray:
        """Contacts per particle among ``active`` particles.

        A self-image contact counts twice (the particle touches its image at +n and at -n), a wall
        contact once.

        Parameters
        ----------
        active : numpy.ndarray of bool, shape (N,), optional
            Particles whose contacts count (contacts with both ends active); all if None.

        Returns
        -------
        numpy.ndarray of int, shape (N,)
            Contact number of every particle (0 for inactive ones).
        """
        keep = self.among(active)
        n = self.n_particles
        return (np.bincount(self.i[keep], minlength=n) + np.bincount(self.j[keep & (self.wall < 0)], minlength=n))


@dataclass(frozen=True)
class ContactNetwork(ContactArrays):
    """Contacts (i, j, image shift n) of a packing (:func:`contact_network`); arrays have length M.

    Without ``wall``, ``periodic`` and ``centre`` the network is periodic.

    Attributes
    ----------
    i, j : numpy.ndarray
        (M,) particle indices of each contact (i <= j; j = i for a wall contact).
    shift : numpy.ndarray
        (M, d) integer lattice image n of j (0 for a wall contact).
    separation : numpy.ndarray
        (M, d) r_ij = x_j + lattice @ n - x_i; for a wall contact h n, from the centre to the
        closest point on the wall (module docstring).
    distance : numpy.ndarray
        (M,) |r_ij| (h for a wall contact).
    contact_distance : numpy.ndarray
        (M,) D_ij = r_i + r_j (r_i for a wall contact).
    positions : numpy.ndarray
        (N, d) the wrapped centres that define ``separation``.
    lattice : numpy.ndarray
        (d, d) lattice vectors as columns.
    delta : float
        The relative gap tolerance the contacts were found with.
    wall : numpy.ndarray or None
        (M,) -1 for a pair, the wall's number for a wall contact (module docstring); None in the
        constructor: pairs only.
    periodic : numpy.ndarray or None
        (d,) bool, the periodic axes; None in the constructor: all.
    centre : numpy.ndarray or None
        (d,) centre of a spherical container, None otherwise.
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    separation: np.ndarray
    distance: np.ndarray
    contact_distance: np.ndarray
    positions: np.ndarray
    lattice: np.ndarray
    delta: float
    wall: np.ndarray | None = None
    periodic: np.ndarray | None = None
    centre: np.ndarray | None = None

    def __post_init__(self):
        super().__post_init__()
        if self.periodic is None:
            object.__setattr__(self, "periodic", np.ones(self.positions.shape[1], dtype=bool))

    @property
    def is_periodic(self) -> bool:
        """Every axis periodic: no walls, the only trivial motions are the d translations."""
        return bool(self.periodic.all())

    @property
    def n_trivial(self) -> int:
        """Number of trivial motions: translations along the periodic axes, or the d(d-1)/2
        rotations about the centre of a spherical container."""
        if self.centre is not None:
            d = self.dim
            return d * (d - 1) // 2
        return int(self.periodic.sum())

    @property
    def normal(self) -> np.ndarray:
        """Unit vectors u_ij from i towards (the image of) j."""
        return self.separation / self.distance[:, None]

    @property
    def gap(self) -> np.ndarray:
        """Absolute gaps h_ij = |r_ij| - D_ij, clipped at 0 (see the module docstring)."""
        return np.maximum(self.distance - self.contact_distance, 0.0)

    @property
    def image_offset(self) -> np.ndarray:
        """The lattice translation w_ij = lattice @ n_ij of each contact, (M, d)."""
        return self.shift @ self.lattice.T

    @property
    def is_self_image(self) -> np.ndarray:
        return (self.i == self.j) & (self.wall < 0)

    def subset(self, mask: np.ndarray) -> ContactNetwork:
        """The network of the contacts in ``mask``, in the same order.

        Parameters
        ----------
        mask : numpy.ndarray of bool, shape (M,), or of int
            Selection (a boolean mask or indices) of the contacts.

        Returns
        -------
        ContactNetwork
            The selected contacts, with the particle data (positions, lattice, delta, periodic axes, centre) unchanged.
        """
        return ContactNetwork(
            i=self.i[mask], j=self.j[mask], shift=self.shift[mask], separation=self.separation[mask],
            distance=self.distance[mask], contact_distance=self.contact_distance[mask],
            positions=self.positions, lattice=self.lattice, delta=self.delta, wall=self.wall[mask],
            periodic=self.periodic, centre=self.centre,
        )


def contact_network(packing: Packing, delta: float) -> ContactNetwork:
    """All potential contacts with relative gap <= delta (Eq. 4.5), with every periodic image,
    and the wall contacts of hard walls or a container (module docstring).

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell, between hard walls or in a spherical container, without
        overlaps (with each other or the walls) beyond its overlap tolerance.
    delta : float
        Relative gap tolerance, 0 < delta < 1: pairs with |r_ij| <= (1 + delta) D_ij are contacts.

    Returns
    -------
    ContactNetwork
        The contacts (i, j, image shift n) with their separations, distances and contact
        distances, the wall contacts after the pairs, the wrapped positions and the lattice.

    Raises
    ------
    InvalidInputError
        If packing is not a :class:`Packing` of hard spheres, delta is not a number with
        0 < delta < 1, or the packing overlaps or crosses a wall beyond its overlap tolerance.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError(
            f"expected a hardpack Packing, got {type(packing).__name__}; build one with "
            "hardpack.Packing(positions, radii, lattice) or hardpack.io.load_packing(path)"
        )
    require_spheres(packing)
    delta = check_delta(delta)
    report = packing.overlap_report(packing.overlap_tol)
    if report.n_overlapping:
        raise InvalidInputError(
            f"the packing overlaps ({report}); jamming tests need a valid hard-sphere packing. "
            "Finish or repair the packing (e.g. rerun the generator to a higher pressure)"
        )
    walls = packing.containment_report(packing.overlap_tol)
    if walls.n_outside:
        raise InvalidInputError(
            f"the packing crosses its walls ({walls}); jamming tests need a valid hard-sphere "
            "packing. Finish or repair the packing"
        )
    pairs = pairs_within(packing, rel_gap=delta)
    positions = wrapped_positions(packing)
    i, j, shift = pairs.i.astype(np.int64), pairs.j.astype(np.int64), pairs.shift.astype(np.int64)
    separation, distance, contact = pairs.separation, pairs.distance, pairs.contact
    wall = np.full(len(i), -1, dtype=np.int64)
    centre = None
    if packing.boundary.kind != "periodic":
        radii = packing.radii
        wc = packing.boundary.wall_contacts(positions, radii, packing.lattice, delta)
        h = radii[wc.particle] * (1.0 + wc.gap)  # centre-wall distance
        i, j = np.r_[i, wc.particle], np.r_[j, wc.particle]
        shift = np.vstack([shift, np.zeros((len(wc), packing.dim), dtype=np.int64)])
        separation = np.vstack([separation, wc.normal * h[:, None]])
        distance, contact = np.r_[distance, h], np.r_[contact, radii[wc.particle]]
        wall = np.r_[wall, _wall_numbers(packing.boundary, wc.normal)]
        if packing.boundary.kind == "spherical_container":
            centre = np.array(packing.boundary.centre, dtype=float)
    return ContactNetwork(
        i=i, j=j, shift=shift, separation=separation, distance=distance, contact_distance=contact,
        positions=positions, lattice=np.array(packing.lattice, dtype=float), delta=delta, wall=wall,
        periodic=packing.boundary.periodic_axes(packing.dim), centre=centre,
    )


def require_spheres(packing: Packing) -> None:
    """Refuse anything but hard spheres (periodic, between hard walls or in a container).

    Parameters
    ----------
    packing : Packing
        The packing to test.

    Raises
    ------
    InvalidInputError
        If its particles are not spheres.
    """
    if packing.shape.kind != "sphere":
        raise InvalidInputError(f"{packing.shape.name} are not supported by the jamming tests yet; they "
                                "handle hard spheres only (ellipsoids: hardpack.jamming.verify_ellipsoids)")


def _wall_numbers(boundary, normal: np.ndarray) -> np.ndarray:
    """Wall numbers (module docstring) of wall contacts from their outward normals."""
    if boundary.kind == "spherical_container":
        return np.zeros(len(normal), dtype=np.int64)
    axis = np.argmax(np.abs(normal), axis=1)
    return (2 * axis + (normal[np.arange(len(normal)), axis] > 0)).astype(np.int64)
