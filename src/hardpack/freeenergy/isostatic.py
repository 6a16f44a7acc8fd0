"""BCMD against the exact jamming simplex of a rattler-free isostatic packing.

Donev 2006, dissertation sec. 6.4.2 and Table 6.1 (Donev et al. 2007, Sec. 4.3): remove the
rattlers, freeze one particle, shrink the spheres by (1 - delta) around their jammed positions
and compare BCMD's Delta f = (d/2) ln(K/K_0), run from Delta mu_max down to the disjoint-cell
point Delta mu_min, with the exact

    Delta f_exact = [ln|P| - sum_{i moving} ln |B_d(Delta mu_min R_i)|] / N_eff,

where P = {dR : -A^T dR <= h} is the linearised jamming polytope with the actual gaps h of the
shrunk contacts (a simplex when M = N_f + 1; Eq. 6.5, :func:`log_simplex_volume`) and the balls
are the final disjoint cells. For unit-diameter spheres and exact contacts this is
f_J - f_c^J (Eq. 6.18); using the actual gaps removes the O(gap / delta) error of a packing
jammed at finite pressure, leaving only the O(delta) linearisation error.

Frozen centre of mass instead of a frozen particle (Donev 2006, sec. 6.3.4.1; Donev et al. 2007,
Appendix B): the coordinate Jacobian N^d shifts the per-particle value by d ln N / N, so the
CM-frame BCMD run is compared with Delta f_exact + d ln N / N (Donev 2006, sec. 6.4.2:
4.9690 - 4.9479 = 3 ln 978 / 978).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.bcmd import cell_neighbours, disjoint_dmu, run_bcmd
from hardpack.freeenergy.simplex import jamming_simplex, log_simplex_volume
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours import pairs_within
from hardpack.geometry.packing import Packing
from hardpack.jamming.contacts import contact_network
from hardpack.jamming.rigidity import rigidity_transpose


def remove_rattlers(packing: Packing, rattler) -> Packing:
    """The packing without the particles flagged in ``rattler`` (boolean mask of length N).

    Parameters
    ----------
    packing : Packing
        The packing.
    rattler : array_like of bool, shape (N,)
        Rattler mask (of the jamming verdict of this packing).

    Returns
    -------
    Packing
        The backbone packing.

    Raises
    ------
    InvalidInputError
        For a mask of the wrong length, or fewer than 2 particles left.
    """
    mask = np.asarray(rattler, dtype=bool)
    if mask.shape != (packing.n_particles,):
        raise InvalidInputError(
            f"the rattler mask has shape {mask.shape}, the packing {packing.n_particles} particles"
            " (pass the jamming verdict of this very packing)"
        )
    if packing.n_particles - mask.sum() < 2:
        raise InvalidInputError("fewer than 2 particles are left after removing the rattlers")
    keep = ~mask
    species = None if packing.species is None else packing.species[keep]
    return packing.replace(
        positions=packing.positions[keep], radii=packing.radii[keep], species=species
    )


@dataclass(frozen=True)
class SimplexReference:
    """Exact jamming-simplex numbers of a backbone shrunk by (1 - delta), particle 0 frozen.

    Attributes
    ----------
    n_particles : int
        Particles of the backbone.
    n_contacts : int
        M, the contacts within ``contact_tol``.
    isostaticity_gap : int
        M - (N_f + 1); 0 for an isostatic backbone, otherwise ``delta_f``, ``f_j`` and
        ``min_force`` are NaN.
    delta_f : float
        The exact Delta f of the module docstring.
    f_j : float
        ln|P_x| / N_eff of the unit-gap simplex (Eq. 6.3).
    min_force : float
        Smallest normalised contact force (unit sum).
    dmu_min : float
        The disjoint-cell point of the shrunk backbone.
    next_gap : float
        The smallest relative gap of a non-contact (inf if none below 1e-3), which must be
        >> delta for the linearised simplex to bound the motion.
    """

    n_particles: int
    n_contacts: int
    isostaticity_gap: int
    delta_f: float
    f_j: float
    min_force: float
    dmu_min: float
    next_gap: float


def check_shrink_gap(delta, contact_tol) -> float:
    """The relative shrink gap delta as a float, refused outside (0, 0.01) (the jamming simplex is
    linear only there), and the contact tolerance, refused outside (0, delta).

    Parameters
    ----------
    delta : float
        Relative shrink gap.
    contact_tol : float
        Contact tolerance.

    Returns
    -------
    float
        delta.

    Raises
    ------
    InvalidInputError
        For values out of range.
    """
    delta = float(delta)
    if not 0.0 < delta < 1e-2:
        raise InvalidInputError(f"delta = {delta!r} must be in (0, 0.01): the simplex is linear")
    if not 0.0 < contact_tol < delta:
        raise InvalidInputError(
            f"contact_tol = {contact_tol!r} must be in (0, delta = {delta}): contacts must close "
            "to much less than the shrink gap"
        )
    return delta


def simplex_reference(backbone: Packing, delta: float, contact_tol: float) -> SimplexReference:
    """Exact reference for BCMD on ``backbone`` shrunk by (1 - delta) (module docstring).

    Contacts are the pairs with relative gap <= contact_tol in the unshrunk backbone (e.g. the
    jamming verifier's tolerance); contact_tol must be well below delta so that shrinking by
    (1 - delta) opens every contact to a gap of about delta.

    Parameters
    ----------
    backbone : Packing
        A rattler-free periodic sphere packing; particle 0 is frozen.
    delta : float
        Relative shrink of the radii, 0 < delta < 0.01 (the simplex is a linearisation).
    contact_tol : float
        Relative gap below which a pair of the unshrunk backbone is a contact,
        0 < contact_tol < delta.

    Returns
    -------
    SimplexReference
        The exact Delta f, f_J, the smallest force, the disjoint-cell point and the next gap;
        a backbone that is not isostatic gets ``isostaticity_gap`` != 0 and NaN values.

    Raises
    ------
    InvalidInputError
        If ``backbone`` is not a periodic sphere packing, ``delta`` is outside (0, 0.01),
        ``contact_tol`` is outside (0, delta), or the simplex is degenerate (see
        :func:`jamming_simplex` and :func:`log_simplex_volume`).
    """
    backbone.require_periodic_spheres("the exact simplex free energy")
    delta = check_shrink_gap(delta, contact_tol)
    net = contact_network(backbone, contact_tol)
    near = pairs_within(backbone, rel_gap=1e-3)
    next_gap = float(np.min(near.gap[near.gap > contact_tol], initial=np.inf))
    n, d = backbone.n_particles, backbone.dim
    n_f = d * (n - 1)
    gap = net.n_contacts - (n_f + 1)
    shrunk = backbone.replace(radii=backbone.radii * (1.0 - delta))
    dmu_min = disjoint_dmu(cell_neighbours(shrunk, 2 * delta))
    if gap != 0:
        return SimplexReference(n, net.n_contacts, gap, np.nan, np.nan, np.nan, dmu_min, next_gap)
    at = rigidity_transpose(net)[:, d:]  # particle 0 frozen: drop its d columns
    js = jamming_simplex(at.T, n_eff=n - 1)  # checks M = N_f + 1 and forces > 0
    gaps = net.distance - (1.0 - delta) * net.contact_distance
    log_v = log_simplex_volume(-at, gaps)
    log_cells = np.sum(np.log(ball_volume(dmu_min * shrunk.radii[1:], d)))
    return SimplexReference(
        n, net.n_contacts, 0, (log_v - log_cells) / (n - 1), js.f_j, float(js.forces.min()),
        dmu_min, next_gap,
    )


def simplex_test(
    packing: Packing,
    rattler,
    *,
    delta: float = 1e-8,
    contact_tol: float = 1e-9,
    dmu_max_ratio: float = 100.0,
    gamma0: float = 0.01,
    theta: float = 1.0,
    frozen: str = "particle",
    seed: int = 0,
) -> xr.Dataset:
    """BCMD of the rattler-free, (1 - delta)-shrunk packing vs its exact simplex value.

    Donev 2006, sec. 6.4.2 and Table 6.1; see the module docstring.

    Parameters
    ----------
    packing : Packing
        A jammed periodic sphere packing.
    rattler : array_like of bool, shape (N,)
        The rattlers of this very packing (e.g. from its jamming verdict); they are removed.
    delta : float, default 1e-8
        Relative shrink of the radii, in (0, 0.01).
    contact_tol : float, default 1e-9
        Relative gap of the contacts in the unshrunk backbone, in (0, delta).
    dmu_max_ratio : float, default 100.0
        BCMD starts at Delta mu_max = dmu_max_ratio times the disjoint-cell point.
    gamma0, theta, frozen, seed
        Passed to :func:`hardpack.freeenergy.bcmd.run_bcmd`.

    Returns
    -------
    xarray.Dataset
        The BCMD dataset (per-segment series) with attributes ``exact`` (Delta f_exact, plus
        d ln N / N for frozen="cm"), ``bcmd`` (BCMD's Delta f), ``rel_diff``, ``isostatic``
        (0/1), ``isostaticity_gap``, ``f_j``, ``min_force``, ``next_gap`` and the costs
        ``seconds_simplex``, ``seconds_bcmd``, ``n_events``. A backbone that is not isostatic
        gets no BCMD run (attributes only, with NaNs and isostatic = 0).

    Raises
    ------
    InvalidInputError
        If ``packing`` is not a periodic sphere packing, the rattler mask does not match it,
        fewer than 2 particles are left, or ``delta`` / ``contact_tol`` or the BCMD parameters
        are out of range (see :func:`simplex_reference` and :func:`run_bcmd`).
    """
    t0 = time.perf_counter()
    packing.require_periodic_spheres("the exact simplex free energy")
    backbone = remove_rattlers(packing, rattler)
    ref = simplex_reference(backbone, delta, contact_tol)
    n, d = ref.n_particles, backbone.dim
    exact = ref.delta_f + (d * np.log(n) / n if frozen == "cm" else 0.0)
    t1 = time.perf_counter()
    attrs = {
        "hardpack_kind": "bcmd_simplex", "n_backbone": n, "dim": d, "n_contacts": ref.n_contacts,
        "isostatic": int(ref.isostaticity_gap == 0), "isostaticity_gap": ref.isostaticity_gap,
        "delta": delta, "contact_tol": contact_tol, "f_j": ref.f_j, "min_force": ref.min_force,
        "next_gap": ref.next_gap,
        "exact": exact, "frozen": frozen, "seconds_simplex": t1 - t0,
    }
    if ref.isostaticity_gap != 0:
        attrs.update(bcmd=np.nan, rel_diff=np.nan, n_events=0, seconds_bcmd=0.0)
        return xr.Dataset(attrs=attrs)
    shrunk = backbone.replace(radii=backbone.radii * (1.0 - delta))
    res = run_bcmd(shrunk, dmu_max=dmu_max_ratio * ref.dmu_min, gamma0=gamma0, theta=theta,
                   frozen=frozen, seed=seed)
    ds = res.to_dataset()
    ds.attrs.update(attrs)
    ds.attrs.update(hardpack_kind="bcmd_simplex", bcmd=res.delta_f,
                    rel_diff=(res.delta_f - exact) / exact,
                    seconds_bcmd=time.perf_counter() - t1)
    return ds
