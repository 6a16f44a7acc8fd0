"""Contact network of a periodic sphere packing from a gap tolerance delta.

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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours import pairs_within, wrapped_positions
from hardpack.geometry.packing import Packing


def check_delta(delta) -> float:
    """Validate the relative gap tolerance: a finite number with 0 < delta < 1."""
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


@dataclass(frozen=True)
class ContactNetwork:
    """Contacts (i, j, image shift n) of a periodic packing; arrays have length M.

    ``positions`` are the wrapped centres used to define ``separation``; ``lattice`` has the
    lattice vectors as columns.
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray  # (M, d) int
    separation: np.ndarray  # (M, d) r_ij = x_j + lattice @ n - x_i
    distance: np.ndarray  # (M,)
    contact_distance: np.ndarray  # (M,) D_ij = r_i + r_j
    positions: np.ndarray  # (N, d) wrapped centres
    lattice: np.ndarray  # (d, d)
    delta: float

    @property
    def n_contacts(self) -> int:
        return len(self.i)

    @property
    def n_particles(self) -> int:
        return self.positions.shape[0]

    @property
    def dim(self) -> int:
        return self.positions.shape[1]

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
        return self.i == self.j

    def counts(self, active: np.ndarray | None = None) -> np.ndarray:
        """Contacts per particle among ``active`` particles (a self-image contact counts twice:
        the particle touches its image at +n and at -n)."""
        keep = self.among(active)
        n = self.n_particles
        return (np.bincount(self.i[keep], minlength=n) + np.bincount(self.j[keep], minlength=n))

    def subset(self, mask: np.ndarray) -> ContactNetwork:
        """The network of the contacts in ``mask`` (boolean (M,) or indices)."""
        return ContactNetwork(
            i=self.i[mask], j=self.j[mask], shift=self.shift[mask], separation=self.separation[mask],
            distance=self.distance[mask], contact_distance=self.contact_distance[mask],
            positions=self.positions, lattice=self.lattice, delta=self.delta,
        )

    def among(self, active: np.ndarray | None) -> np.ndarray:
        """Boolean mask of contacts whose both ends are ``active`` (all if None)."""
        if active is None:
            return np.ones(self.n_contacts, dtype=bool)
        return active[self.i] & active[self.j]


def contact_network(packing: Packing, delta: float) -> ContactNetwork:
    """All potential contacts with relative gap <= delta (Eq. 4.5), with every periodic image.

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell, without overlaps beyond its overlap tolerance.
    delta : float
        Relative gap tolerance, 0 < delta < 1: pairs with |r_ij| <= (1 + delta) D_ij are contacts.

    Returns
    -------
    ContactNetwork
        The contacts (i, j, image shift n) with their separations, distances and contact
        distances, the wrapped positions and the lattice.

    Raises
    ------
    InvalidInputError
        If packing is not a :class:`Packing` of hard spheres in a periodic cell, delta is not a
        number with 0 < delta < 1, or the packing overlaps beyond its overlap tolerance.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError(
            f"expected a hardpack Packing, got {type(packing).__name__}; build one with "
            "hardpack.Packing(positions, radii, lattice) or hardpack.io.load_packing(path)"
        )
    packing.require_periodic_spheres("the jamming tests")
    delta = check_delta(delta)
    report = packing.overlap_report(packing.overlap_tol)
    if report.n_overlapping:
        raise InvalidInputError(
            f"the packing overlaps ({report}); jamming tests need a valid hard-sphere packing. "
            "Finish or repair the packing (e.g. rerun the generator to a higher pressure)"
        )
    pairs = pairs_within(packing, rel_gap=delta)
    return ContactNetwork(
        i=pairs.i.astype(np.int64),
        j=pairs.j.astype(np.int64),
        shift=pairs.shift.astype(np.int64),
        separation=pairs.separation,
        distance=pairs.distance,
        contact_distance=pairs.contact,
        positions=wrapped_positions(packing),
        lattice=np.array(packing.lattice, dtype=float),
        delta=delta,
    )
