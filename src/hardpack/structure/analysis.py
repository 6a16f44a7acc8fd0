"""One call for the standard structure analysis of a packing (what ``hardpack structure`` writes).

Merges g2 (absolute and scaled), Z(l) (with and without rattlers when a mask is given), the
shell-averaged S(k) with the linear S(0) fit over kD < 2 pi 0.4 (Donev 2006, sec. 10.3,
Fig. 10.2; D = mean diameter), and the order metrics of the dimension: Q6 (bond-averaged), mean
q6, T and the q6 crystallinity in 3D; psi6 and T in 2D; T in d >= 4.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.structure.channels import channel_histogram, channel_radii
from hardpack.structure.order import (
    crystallinity,
    psi6,
    steinhardt,
    translational_order,
)
from hardpack.structure.pair import (
    DEFAULT_CONTACT_TOL,
    NEAR_CONTACT_FIT,
    cumulative_coordination,
    fit_coordination_power_law,
    pair_correlation,
)
from hardpack.structure.sk import extrapolate_s0, structure_factor

S0_FIT_KD = 2 * np.pi * 0.4


def analyse(packing, r_max: float | None = None, k_max: float | None = None, rattlers=None,
            contact_tol: float = DEFAULT_CONTACT_TOL, gap_max: float = 0.5,
            dr: float | None = None, order: bool = True, channels: bool = True) -> xr.Dataset:
    """Structure Dataset of one packing; ``k_max`` defaults to 20 / mean diameter.

    Also the near-contact power law Z(l) - Z_c = a l^alpha fitted over :data:`NEAR_CONTACT_FIT`
    (rattler-free backbone when a rattler mask is given; NaN when the window holds no gaps) and,
    with ``channels`` in d = 2, 3, the histogram of channel radii R / r (Ogarko ch. 4, bin 0.01).

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing.
    r_max, dr : float, optional
        Range and bin width of g2 (:func:`hardpack.structure.pair.pair_correlation` defaults).
    k_max : float, optional
        Largest wavenumber of S(k); default 20 / mean diameter.
    rattlers : array_like of bool, shape (N,), optional
        Rattler mask; Z(l) and the near-contact fit are then also given without rattlers.
    contact_tol : float, default DEFAULT_CONTACT_TOL
        Relative gap below which a pair is a contact in g2 and Z(l).
    gap_max : float, default 0.5
        Largest relative gap l of Z(l).
    order : bool, default True
        Add the order metrics of the dimension.
    channels : bool, default True
        Add the channel-radius histogram (d = 2, 3).

    Returns
    -------
    xarray.Dataset
        The merged variables of g2, Z(l), S(k), ``channel_density``, per-particle ``q6`` and
        ``solid`` (3D), and the scalars ``S0``, ``S0_err``, ``S0_slope`` (NaN with too few
        k-shells), ``alpha``, ``alpha_err``, ``alpha_amplitude`` (NaN without gaps in the
        window), ``n_channels``, ``T``, ``Q6``, ``q6_mean``, ``crystallinity`` (3D),
        ``psi6_global``, ``psi6_local_mean`` (2D); attributes ``hardpack_kind`` = "structure",
        ``n_particles``, ``dim``, ``phi``, ``mean_diameter`` and the conventions used.

    Raises
    ------
    InvalidInputError
        If the packing is not a periodic sphere packing, or a parameter is refused by the
        underlying functions.
    """
    packing.require_periodic_spheres("the structure analysis")
    diameter = 2.0 * float(np.mean(packing.radii))
    k_max = 20.0 / diameter if k_max is None else k_max
    g2 = pair_correlation(packing, r_max=r_max, dr=dr, contact_tol=contact_tol)
    z = cumulative_coordination(packing, gap_max=gap_max, rattlers=rattlers, contact_tol=contact_tol)
    sk = structure_factor(packing, k_max)
    parts = [ds.copy() for ds in (g2, z, sk)]
    for ds in parts:
        ds.attrs = {}
    scalars = {}
    try:
        s0, s0_err, coef = extrapolate_s0(sk, S0_FIT_KD / diameter, "linear")
        scalars.update(S0=s0, S0_err=s0_err, S0_slope=float(coef[1]))
    except InvalidInputError:  # too few k-shells below the fit range (small systems)
        scalars.update(S0=np.nan, S0_err=np.nan, S0_slope=np.nan)
    try:
        fit = fit_coordination_power_law(z, *NEAR_CONTACT_FIT)
        scalars.update(alpha=fit.alpha, alpha_err=fit.alpha_err, alpha_amplitude=fit.amplitude)
    except InvalidInputError:  # no gaps in the window (small or crystalline packings)
        scalars.update(alpha=np.nan, alpha_err=np.nan, alpha_amplitude=np.nan)
    if channels and packing.dim in (2, 3):
        hist = channel_histogram(channel_radii(packing))
        parts.append(xr.Dataset(dict(channel_density=hist["density"]), attrs={}))
        scalars["n_channels"] = hist.attrs["n_channels"]
    if order and packing.dim >= 2:
        scalars["T"] = translational_order(packing)
        if packing.dim == 3:
            st = steinhardt(packing)
            scalars.update(Q6=float(st.Q6), q6_mean=float(np.nanmean(st.q6)))
            cr = crystallinity(packing)
            scalars["crystallinity"] = float(cr.crystallinity)
            parts.append(xr.Dataset(dict(q6=st.q6, solid=cr.solid)))
        elif packing.dim == 2:
            ps = psi6(packing)
            scalars.update(psi6_global=float(ps.psi6_global), psi6_local_mean=float(ps.psi6_local_mean))
    parts.append(xr.Dataset({k: ((), v) for k, v in scalars.items()}))
    out = xr.merge(parts, compat="no_conflicts")
    out.attrs = dict(
        hardpack_kind="structure", n_particles=packing.n_particles, dim=packing.dim,
        phi=packing.phi, mean_diameter=diameter,
        radius_ratio=float(packing.radii.max() / packing.radii.min()),
        alpha_window=list(NEAR_CONTACT_FIT), contact_tol=contact_tol, k_max=float(k_max),
        s0_fit="linear S0 + s1 k over shells with k D < 2 pi 0.4",
        g2_normalisation=g2.attrs["normalisation"], gap_definition=z.attrs["gap_definition"],
        order_neighbours="Q6/q6: within 1.2 contact distances; crystallinity: regular triangulation",
    )
    return out
