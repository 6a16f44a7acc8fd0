"""Near pairs of an ellipsoid (or ellipse) packing with their Perram-Wertheim potentials.

Candidates come from the bounding spheres (:func:`hardpack.geometry.neighbours.pairs_within`, the
largest semiaxis as radius, every periodic image). The scale factor mu = sqrt(zeta + 1) that brings
two ellipsoids into tangency (Donev 2006, Sec. 2.2.2.1) is at least distance / (R_i + R_j) (the
bounding spheres scaled by mu meet), so the candidates within (1 + rel_gap)(R_i + R_j) hold every
pair with mu <= 1 + rel_gap. For spheres mu = distance / (r_i + r_j), so 1 - mu is the relative
overlap of the sphere overlap check and mu - 1 its relative gap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.contact import inverse_shapes, pair_potentials
from hardpack.geometry.neighbours import PairList, pairs_within


@dataclass(frozen=True)
class PotentialPairs:
    """Candidate pairs (``pairs``, a :class:`PairList` of the bounding spheres) with their
    Perram-Wertheim potential ``zeta`` = mu^2 - 1 and maximiser ``lam`` (Donev 2006, Eqs. 2.10-2.11).

    Attributes
    ----------
    pairs : PairList
        The candidate pairs (i, j, lattice image), M of them.
    zeta : numpy.ndarray of float, shape (M,)
        mu^2 - 1 of every pair (> 0 disjoint).
    lam : numpy.ndarray of float, shape (M,)
        The maximiser Lambda in (0, 1).
    """

    pairs: PairList
    zeta: np.ndarray
    lam: np.ndarray

    def __len__(self) -> int:
        return len(self.zeta)

    @property
    def mu(self) -> np.ndarray:
        """Common scale factor to tangency, sqrt(zeta + 1) (< 1 overlapping, 1 touching)."""
        return np.sqrt(self.zeta + 1.0)

    def subset(self, mask) -> PotentialPairs:
        """The pairs selected by ``mask``, in the same order.

        Parameters
        ----------
        mask : numpy.ndarray of bool, shape (M,), or of int
            Selection (a boolean mask or indices) of the pairs.

        Returns
        -------
        PotentialPairs
            The selected pairs with their zeta and lam.
        """
        return PotentialPairs(self.pairs.subset(mask), self.zeta[mask], self.lam[mask])


def potential_pairs(packing, rel_gap: float = 0.0) -> PotentialPairs:
    """Every pair of ``packing`` whose bounding spheres are within (1 + rel_gap)(R_i + R_j), with its
    Perram-Wertheim potential (module docstring).

    Parameters
    ----------
    packing : hardpack.geometry.Packing
        A packing of ellipsoids or ellipses.
    rel_gap : float, default 0.0
        Relative range of the search, >= 0: every pair with mu <= 1 + rel_gap is included.

    Returns
    -------
    PotentialPairs
        The candidate pairs (each once, sorted as by ``pairs_within``) with zeta and lambda.

    Raises
    ------
    InvalidInputError
        If the packing does not hold ellipsoids, or ``rel_gap`` is negative or not finite.
    """
    if packing.shape.kind != "ellipsoid":
        raise InvalidInputError(f"potential_pairs needs a packing of ellipsoids, got {packing.shape.name}; "
                                "pairs of spheres come from hardpack.geometry.pairs_within")
    if not (np.isfinite(rel_gap) and rel_gap >= 0):
        raise InvalidInputError(f"rel_gap must be a finite number >= 0, got {rel_gap}")
    shape = packing.shape
    pairs = pairs_within(packing, rel_gap=rel_gap)
    inv = inverse_shapes(shape.semiaxes, shape.orientations.reshape(shape.n_particles, -1))
    zeta, lam = pair_potentials(pairs.separation, pairs.i, pairs.j, inv, np.asarray(shape.bounding_radii))
    return PotentialPairs(pairs, zeta, lam)
