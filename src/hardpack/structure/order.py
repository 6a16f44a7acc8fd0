"""Order metrics: Steinhardt Q_l / q_l, psi_6, translational order T, q6 crystallinity, order map.

**Bond-orientational order** (Steinhardt, Nelson & Ronchetti 1983; used by Donev ch. 9 Fig. 9.13):
q_lm(i) = (1/N_b(i)) sum_j Y_lm(r_ij), q_l(i) = sqrt(4 pi / (2l + 1) sum_m |q_lm(i)|^2), and the
global Q_l = sqrt(4 pi / (2l + 1) sum_m |<Y_lm>|^2) with the average over all bonds (each bond
once per direction; for even l the direction does not matter). freud's Steinhardt ``order``
averages q_lm over particles instead; the two agree when every particle has the same number of
bonds; ``particle_weighted=True`` gives freud's convention. Reference values with the default
neighbours (within 1.2 contact distances): FCC 0.5745, HCP 0.4848, BCC 0.5106 (8 + 6
neighbours), SC 0.3536.

**psi_6** (2D): psi_6(i) = (1/N_b(i)) sum_j exp(6 i theta_ij); reported as the global |<psi_6(i)>|
and the mean local |psi_6(i)|; both are 1 for the triangular lattice.

**Coordination defects** (2D): the fraction of disks whose number of neighbours in the regular
(weighted Delaunay) triangulation is not six; 0 for the triangular lattice, and the topological
defects (5-7 pairs, vacancies, grain boundaries) of a frozen disk crystal otherwise.

**Translational order T** (Torquato, Truskett & Debenedetti 2000, as used by Torquato & Jiao 2010,
Sec. VI, Eq. 22): T = |sum_i (n_i - n_i^ideal)| / sum_i (n_i^ref - n_i^ideal) over the
first N_s neighbour shells of the reference crystal at the packing's number density (FCC in 3D;
triangular in 2D, D_d in d >= 4). n_i = mean number of neighbours (all periodic images,
including a particle's own images) in the shell [a_i - w/2, a_i + w/2], n_i^ideal = rho times the
shell volume, n_i^ref = the crystal's coordination number of shell i. The seed gives neither the
shell width nor N_s; the defaults here, N_s = 7 and w = 0.98 times the smallest spacing of
consecutive reference shells (0.192 a_1 for FCC, whose 6th and 7th shells are a_1 (sqrt 7 -
sqrt 6) = 0.196 a_1 apart), are our choice, so T values are comparable between our packings but
not digit by digit with the published order map.
T = 1 exactly for the reference crystal; for N ideal-gas points E[T numerator] = -sum n_i^ideal/N
(the O(1/N) finite-size bias of counting N - 1 partners against rho = N/V).

**Crystallinity** (Ogarko 2014, sec. 3.3.3, Eqs. 3.56-3.57): normalised q6 vectors
q~_6m(i) = q_6m(i) / |q_6(i)|, bond order d6(i, j) = Re sum_m q~_6m(i) q~*_6m(j); a bond is
connected if d6 > 0.65 and a particle is solid-like with >= 6 connected bonds; p_c = fraction of
solid-like particles. Neighbours from the weighted Delaunay (regular) triangulation as in the
source, or from a distance cutoff.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from scipy.special import sph_harm_y

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import unit_ball_volume
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.neighbours import pairs_within
from hardpack.structure.tessellation import NeighbourList, neighbour_list


def _require_dim(packing, dims, what):
    if packing.dim not in dims:
        raise InvalidInputError(f"{what} is defined for d in {dims}, the packing has d = {packing.dim}")


def bond_harmonics(separation: np.ndarray, l: int) -> np.ndarray:
    """Y_lm of the bond directions, shape (n_bonds, 2l + 1) for m = -l..l (3D bonds).

    Parameters
    ----------
    separation : numpy.ndarray, shape (n_bonds, 3)
        Bond vectors (non-zero); only their directions matter.
    l : int
        Degree of the spherical harmonics, >= 0.

    Returns
    -------
    numpy.ndarray of complex, shape (n_bonds, 2l + 1)
        Y_lm(theta, phi) (scipy's ``sph_harm_y`` convention) for m = -l..l.
    """
    r = np.linalg.norm(separation, axis=1)
    theta = np.arccos(np.clip(separation[:, 2] / r, -1.0, 1.0))
    phi = np.mod(np.arctan2(separation[:, 1], separation[:, 0]), 2 * np.pi)
    m = np.arange(-l, l + 1)
    return sph_harm_y(l, m[None, :], theta[:, None], phi[:, None])


def _per_particle_mean(values, nl: NeighbourList, n: int):
    counts = nl.counts
    out = np.zeros((n,) + values.shape[1:], dtype=values.dtype)
    np.add.at(out, nl.i, values)
    with np.errstate(invalid="ignore", divide="ignore"):
        return out / counts.reshape((-1,) + (1,) * (values.ndim - 1))


def local_qlm(packing, l: int = 6, neighbours=1.2):
    """q_lm(i) (N, 2l + 1) and the neighbour list used (NaN rows for particles without bonds).

    Parameters
    ----------
    packing : Packing
        A 3D periodic sphere packing.
    l : int, default 6
        Degree, a non-negative integer.
    neighbours : "delaunay", float or NeighbourList, default 1.2
        Neighbour specification of :func:`hardpack.structure.tessellation.neighbour_list`: the
        regular triangulation, a cutoff in contact distances, or a ready list.

    Returns
    -------
    qlm : numpy.ndarray of complex, shape (N, 2l + 1)
        q_lm(i) = (1/N_b(i)) sum_j Y_lm(r_ij); NaN rows for particles without bonds.
    neighbours : NeighbourList
        The neighbour list used.

    Raises
    ------
    InvalidInputError
        If the packing is not 3D, ``l`` is not a non-negative integer, or ``neighbours`` is
        not a valid specification.
    """
    _require_dim(packing, (3,), "Steinhardt q_l")
    if int(l) != l or l < 0:
        raise InvalidInputError(f"l must be a non-negative integer, got {l!r}")
    nl = neighbour_list(packing, neighbours)
    return _per_particle_mean(bond_harmonics(nl.separation, int(l)), nl, packing.n_particles), nl


def _invariant(qlm, l):
    return np.sqrt(4 * np.pi / (2 * l + 1) * np.sum(np.abs(qlm) ** 2, axis=-1))


def steinhardt(packing, l: int = 6, neighbours=1.2, particle_weighted: bool = False) -> xr.Dataset:
    """Global Q_l (bond-averaged, or particle-averaged as freud) and local q_l(i).

    Steinhardt, Nelson & Ronchetti 1983; conventions in the module docstring.

    Parameters
    ----------
    packing : Packing
        A 3D periodic sphere packing.
    l : int, default 6
        Degree, a non-negative integer.
    neighbours : "delaunay", float or NeighbourList, default 1.2
        Neighbour specification of :func:`hardpack.structure.tessellation.neighbour_list`: the
        regular triangulation, a cutoff in contact distances, or a ready list.
    particle_weighted : bool, default False
        Average q_lm over particles (freud's ``order``) instead of over bonds.

    Returns
    -------
    xarray.Dataset
        Scalar ``Q{l}``, per-particle ``q{l}`` and ``n_bonds`` (dim ``particle``); attributes
        ``l`` and ``weighting``.

    Raises
    ------
    InvalidInputError
        As :func:`local_qlm`.
    """
    qlm, nl = local_qlm(packing, l, neighbours)
    if particle_weighted:
        glob = np.nanmean(qlm, axis=0)
    else:
        glob = bond_harmonics(nl.separation, int(l)).mean(axis=0) if len(nl.i) else np.full(2 * l + 1, np.nan)
    return xr.Dataset(
        data_vars={f"Q{l}": ((), float(_invariant(glob, l))),
                   f"q{l}": ("particle", _invariant(qlm, l)),
                   "n_bonds": ("particle", nl.counts)},
        attrs=dict(l=int(l), weighting="particle" if particle_weighted else "bond"),
    )


def psi6(packing, neighbours=1.2) -> xr.Dataset:
    """Hexatic order psi_6 in 2D: local complex psi6(i), global |<psi6>| and <|psi6(i)|>.

    Parameters
    ----------
    packing : Packing
        A 2D periodic sphere (disk) packing.
    neighbours : "delaunay", float or NeighbourList, default 1.2
        Neighbour specification of :func:`hardpack.structure.tessellation.neighbour_list`: the
        regular triangulation, a cutoff in contact distances, or a ready list.

    Returns
    -------
    xarray.Dataset
        Scalars ``psi6_global`` |<psi6(i)>| and ``psi6_local_mean`` <|psi6(i)|>, per-particle
        ``psi6_abs`` and ``n_bonds`` (dim ``particle``); both scalars are 1 for the triangular
        lattice.

    Raises
    ------
    InvalidInputError
        If the packing is not 2D or ``neighbours`` is not a valid specification.
    """
    _require_dim(packing, (2,), "psi_6")
    nl = neighbour_list(packing, neighbours)
    theta = np.arctan2(nl.separation[:, 1], nl.separation[:, 0])
    local = _per_particle_mean(np.exp(6j * theta), nl, packing.n_particles)
    return xr.Dataset(data_vars=dict(
        psi6_global=((), float(np.abs(np.nanmean(local)))),
        psi6_local_mean=((), float(np.nanmean(np.abs(local)))),
        psi6_abs=("particle", np.abs(local)), n_bonds=("particle", nl.counts)))


def coordination_defects(packing) -> float:
    """Fraction of the disks of a 2D packing that do not have six neighbours in the regular
    (weighted Delaunay) triangulation: the topological defects of a disk crystal.

    Four or more cocircular centres (a vacancy in a perfect lattice) have no unique triangulation
    (:func:`hardpack.structure.tessellation.regular_neighbours`), so the count around them is one
    of several; packings from simulations are not degenerate.

    Parameters
    ----------
    packing : Packing
        A 2D periodic disk packing.

    Returns
    -------
    float
        The fraction, in [0, 1]; 0 for the triangular lattice.

    Raises
    ------
    InvalidInputError
        If the packing is not 2D.
    """
    _require_dim(packing, (2,), "coordination defects")
    counts = neighbour_list(packing, "delaunay").counts
    return float(np.mean(counts != 6))


_REFERENCE = {2: "triangular", 3: "fcc"}


def _reference_shells(d: int, n_shells: int):
    """(shell radii in units of the NN distance, coordination numbers, number density at NN 1)."""
    name = _REFERENCE.get(d, f"D{d}")
    ref = lattice_packing(name, 1)
    k = 2
    while True:
        pairs = pairs_within(ref, cutoff=float(k))
        dist = pairs.distance
        r = np.unique(np.round(dist, 9))
        if len(r) > n_shells:
            break
        k += 1
    radii = r[:n_shells]
    counts = np.array([2.0 * np.count_nonzero(np.abs(dist - a) < 1e-6) for a in radii]) / ref.n_particles
    return radii, counts, ref.n_particles / ref.volume


def translational_order(packing, n_shells: int = 7, width: float | None = None) -> float:
    """Translational order metric T (module docstring); ``width`` in units of the NN distance
    (default 0.98 times the smallest spacing of the first ``n_shells`` reference shells).

    Torquato, Truskett & Debenedetti 2000, as used by Torquato & Jiao 2010; the shell width and
    count are our choice (module docstring).

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing, d >= 2.
    n_shells : int, default 7
        Neighbour shells N_s of the reference crystal (FCC in 3D, triangular in 2D, D_d in
        d >= 4) at the packing's number density; a positive integer.
    width : float, optional
        Shell width in units of the reference nearest-neighbour distance, below the smallest
        spacing of the first ``n_shells`` shells.

    Returns
    -------
    float
        T: 1 for the reference crystal, ~0 for an ideal gas.

    Raises
    ------
    InvalidInputError
        If the packing is not a periodic sphere packing, d < 2, ``n_shells`` is not a positive
        integer, or ``width`` would make the shells overlap (or is not positive).
    """
    packing.require_periodic_spheres("the structure analysis")
    if int(n_shells) != n_shells or n_shells < 1:
        raise InvalidInputError(f"n_shells must be a positive integer, got {n_shells!r}")
    d = packing.dim
    if d < 2:
        raise InvalidInputError("T needs a reference crystal; d >= 2 is required")
    radii, ref_counts, ref_density = _reference_shells(d, int(n_shells))
    gaps = np.diff(radii)
    width = 0.98 * gaps.min() if width is None else width
    if not (0 < width < gaps.min()):
        raise InvalidInputError(
            f"width must be in (0, {gaps.min():.4f}) so that the first {n_shells} reference "
            f"shells do not overlap, got {width!r}")
    n = packing.n_particles
    rho = n / packing.volume
    a1 = (ref_density / rho) ** (1.0 / d)  # NN distance of the reference crystal at density rho
    lo, hi = (radii - width / 2) * a1, (radii + width / 2) * a1
    pairs = pairs_within(packing, cutoff=float(hi[-1]))
    which = np.searchsorted(hi, pairs.distance, side="left")
    inside = (which < len(hi)) & (pairs.distance >= lo[np.minimum(which, len(lo) - 1)])
    n_i = 2.0 * np.bincount(which[inside], minlength=len(radii)) / n
    ideal = rho * unit_ball_volume(d) * (hi**d - lo**d)
    return float(abs(np.sum(n_i - ideal)) / np.sum(ref_counts - ideal))


def crystallinity(packing, neighbours="delaunay", threshold: float = 0.65,
                  min_connections: int = 6) -> xr.Dataset:
    """Ogarko's q6 bond criterion (module docstring): solid-like flags, connections and p_c.

    Ogarko 2014, ch. 3.3.

    Parameters
    ----------
    packing : Packing
        A 3D periodic sphere packing.
    neighbours : "delaunay", float or NeighbourList, default "delaunay"
        Neighbour specification (:func:`hardpack.structure.tessellation.neighbour_list`); the
        regular triangulation is the source's choice.
    threshold : float, default 0.65
        A bond is connected when d6(i, j) exceeds it.
    min_connections : int, default 6
        Connected bonds from which a particle is solid-like.

    Returns
    -------
    xarray.Dataset
        Per-particle ``solid``, ``connections`` and ``n_bonds`` (dim ``particle``), the scalar
        ``crystallinity`` p_c (fraction of solid-like particles); attributes ``threshold`` and
        ``min_connections``.

    Raises
    ------
    InvalidInputError
        If the packing is not 3D or ``neighbours`` is not a valid specification.
    """
    qlm, nl = local_qlm(packing, 6, neighbours)
    norm = np.linalg.norm(qlm, axis=1)
    unit = qlm / np.where(norm > 0, norm, np.nan)[:, None]
    d6 = np.real(np.sum(unit[nl.i] * np.conj(unit[nl.j]), axis=1))
    connected = np.nan_to_num(d6, nan=-1.0) > threshold
    connections = np.bincount(nl.i[connected], minlength=packing.n_particles)
    solid = connections >= min_connections
    return xr.Dataset(
        data_vars=dict(solid=("particle", solid), connections=("particle", connections),
                       n_bonds=("particle", nl.counts),
                       crystallinity=((), float(solid.mean()))),
        attrs=dict(threshold=threshold, min_connections=min_connections),
    )


def order_map(packings, n_shells: int = 7, width: float | None = None) -> xr.Dataset:
    """The (phi, T) order map of Torquato & Jiao (2010, Fig. 6): one point per packing.

    Parameters
    ----------
    packings : iterable of Packing
        The packings, at least one.
    n_shells, width
        As in :func:`translational_order`.

    Returns
    -------
    xarray.Dataset
        ``phi`` and ``T`` along ``packing``; attributes ``n_shells`` and ``width``.

    Raises
    ------
    InvalidInputError
        If there is no packing, or as :func:`translational_order`.
    """
    packings = list(packings)
    if not packings:
        raise InvalidInputError("order_map needs at least one packing")
    phi = [p.phi for p in packings]
    t = [translational_order(p, n_shells, width) for p in packings]
    return xr.Dataset(dict(phi=("packing", phi), T=("packing", t)),
                      attrs=dict(n_shells=n_shells, width="default" if width is None else width))
