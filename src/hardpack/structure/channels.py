"""Channel-size ("four-point") analysis of Ogarko 2014, sec. 4.2.

For every particle i and every combination of three of its neighbours (all C(n_i, 3) triples
of its regular-triangulation neighbours, not only Delaunay faces; periodic images as seen
from i), keep the triangle of the three neighbour centres only if it is acute with the
tolerance eps = 1 - 1e-12: a^2 + b^2 > eps c^2 for all three edge orderings, so exact right
angles (square arrangements) are kept (Ogarko 2014, sec. 4.3, footnote on the acute test). In the
plane of the triangle the three spheres are circles of their full radii; the channel is the circle
externally tangent to all three (Apollonius problem, centre p and radius R with |p - c_k| = R + r_k). Subtracting the
k = 1 equation from the others gives p linear in R, and the k = 1 equation then a quadratic in
R. The channel is the smallest positive root whose centre lies inside the triangle, else the
smallest positive root (no centre lies in the circle since |p - c_k| = R + r_k > R; for acute
triangles of equal spheres the root is unique and inside). Triangles without a positive root
are skipped and counted. The statistic is the histogram of R / r_i (central radius,
Ogarko 2014, sec. 4.4.3), bin 0.01.

Exact values: three mutually touching equal spheres 2/sqrt(3) - 1 = 0.1547; a square of
touching equal spheres (a right isosceles triangle of neighbours) sqrt(2) - 1 = 0.4142;
three neighbours coplanar with and touching the central sphere at 120 degrees, 1 (Ogarko 2014, sec. 4.4.1).
Ideal gas at phi = 0.0014, acute triangles only: roughly Gaussian, mean ~15.9, sigma ~4 (Ogarko 2014, Fig. 4.2).
"""

from __future__ import annotations

import numba
import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.structure.tessellation import neighbour_list

ACUTE_EPS = 1.0 - 1e-12


@numba.njit(cache=True)
def apollonius_radius(p1, p2, p3, r1, r2, r3, eps=ACUTE_EPS):
    """Channel radius of three spheres: the circle externally tangent to all three in the plane
    of their centres (Apollonius problem; Ogarko 2014, sec. 4.2; module docstring).

    Parameters
    ----------
    p1, p2, p3 : numpy.ndarray
        (d,) centres, any d >= 2.
    r1, r2, r3 : float
        Radii.
    eps : float, default :data:`ACUTE_EPS`
        Acute-triangle tolerance: a^2 + b^2 > eps c^2 for all three edge orderings.

    Returns
    -------
    float
        The smallest positive root R whose centre lies inside the triangle, else the smallest
        positive root; -1.0 if the triangle is not acute (tolerance eps), NaN if there is no
        positive root.
    """
    d = p1.size
    a2 = 0.0
    b2 = 0.0
    c2 = 0.0
    for k in range(d):
        a2 += (p2[k] - p3[k]) ** 2
        b2 += (p1[k] - p3[k]) ** 2
        c2 += (p1[k] - p2[k]) ** 2
    if not (a2 + b2 > eps * c2 and b2 + c2 > eps * a2 and a2 + c2 > eps * b2):
        return -1.0
    # orthonormal in-plane frame: e1 along p2 - p1, e2 from Gram-Schmidt of p3 - p1
    len1 = np.sqrt(c2)
    u2 = 0.0  # coordinates: c1 = (0, 0), c2 = (len1, 0), c3 = (u2, v2)
    for k in range(d):
        u2 += (p3[k] - p1[k]) * (p2[k] - p1[k]) / len1
    v2 = np.sqrt(max(b2 - u2 * u2, 0.0))
    if v2 <= 1e-15 * len1:
        return np.nan
    # 2 c_k . p + 2 (r_k - r_1) R = |c_k|^2 - r_k^2 + r_1^2  for k = 2, 3, with c_1 = 0
    m11, m12 = 2.0 * len1, 0.0
    m21, m22 = 2.0 * u2, 2.0 * v2
    g1 = len1 * len1 - r2 * r2 + r1 * r1
    g2 = u2 * u2 + v2 * v2 - r3 * r3 + r1 * r1
    h1 = -2.0 * (r2 - r1)
    h2 = -2.0 * (r3 - r1)
    det = m11 * m22 - m12 * m21
    # p = q0 + R q1
    q0x = (g1 * m22 - m12 * g2) / det
    q0y = (m11 * g2 - m21 * g1) / det
    q1x = (h1 * m22 - m12 * h2) / det
    q1y = (m11 * h2 - m21 * h1) / det
    # |p|^2 = (R + r1)^2  ->  A R^2 + B R + C = 0
    qa = q1x * q1x + q1y * q1y - 1.0
    qb = 2.0 * (q0x * q1x + q0y * q1y - r1)
    qc = q0x * q0x + q0y * q0y - r1 * r1
    roots = np.empty(2)
    n_roots = 0
    if abs(qa) < 1e-14:
        if qb != 0.0:
            roots[0] = -qc / qb
            n_roots = 1
    else:
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            sq = np.sqrt(disc)
            roots[0] = (-qb - sq) / (2.0 * qa)
            roots[1] = (-qb + sq) / (2.0 * qa)
            n_roots = 2
    inside = np.nan
    outside = np.nan
    for t in range(n_roots):
        rad = roots[t]
        if not rad > 0.0:
            continue
        px, py = q0x + rad * q1x, q0y + rad * q1y
        # barycentric test: p inside the triangle (0,0), (len1,0), (u2,v2)
        l3 = py / v2
        l2 = (px - u2 * l3) / len1
        l1 = 1.0 - l2 - l3
        if l1 >= -1e-12 and l2 >= -1e-12 and l3 >= -1e-12:
            if np.isnan(inside) or rad < inside:
                inside = rad
        elif np.isnan(outside) or rad < outside:
            outside = rad
    return outside if np.isnan(inside) else inside


@numba.njit(cache=True)
def _channel_kernel(start, separation, nb_radius, radii, eps):
    n = radii.size
    total = 0
    for i in range(n):
        k = start[i + 1] - start[i]
        total += k * (k - 1) * (k - 2) // 6
    ratio = np.empty(total)
    owner = np.empty(total, dtype=np.int64)
    n_out = 0
    n_obtuse = 0
    n_failed = 0
    for i in range(n):
        s0, s1 = start[i], start[i + 1]
        for a in range(s0, s1):
            for b in range(a + 1, s1):
                for c in range(b + 1, s1):
                    rad = apollonius_radius(separation[a], separation[b], separation[c],
                                            nb_radius[a], nb_radius[b], nb_radius[c], eps)
                    if rad == -1.0:
                        n_obtuse += 1
                    elif np.isnan(rad):
                        n_failed += 1
                    else:
                        ratio[n_out] = rad / radii[i]
                        owner[n_out] = i
                        n_out += 1
    return ratio[:n_out], owner[:n_out], n_obtuse, n_failed


def channel_radii(packing, neighbours="delaunay", eps: float = ACUTE_EPS) -> xr.Dataset:
    """Channel radii R / r_i of all acute neighbour triangles (module docstring).

    ``neighbours``: "delaunay" (weighted regular triangulation, the source's choice), a cutoff
    in contact distances, or a NeighbourList. Returns a Dataset on dim ``channel`` with
    ``ratio`` and ``particle``, plus scalar counts ``n_obtuse`` and ``n_failed``.

    Ogarko 2014, ch. 4.

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing, d >= 2.
    neighbours : "delaunay", float or NeighbourList, default "delaunay"
        Neighbour specification (:func:`hardpack.structure.tessellation.neighbour_list`).
    eps : float, default 1 - 1e-12
        Acute-triangle tolerance, in (0, 1]: a^2 + b^2 > eps c^2 for every ordering.

    Returns
    -------
    xarray.Dataset
        ``ratio`` R / r_i and the central ``particle`` i of every channel (dim ``channel``),
        scalar counts ``n_obtuse`` (triangles not acute) and ``n_failed`` (no positive root);
        attributes ``eps`` and ``definition``.

    Raises
    ------
    InvalidInputError
        If d < 2, ``eps`` is not in (0, 1], or ``neighbours`` is not a valid specification.
    """
    if packing.dim < 2:
        raise InvalidInputError("channel analysis needs d >= 2")
    if not 0 < eps <= 1:
        raise InvalidInputError(f"eps must be in (0, 1], got {eps!r}")
    nl = neighbour_list(packing, neighbours)
    radii = np.ascontiguousarray(packing.radii, dtype=float)
    ratio, owner, n_obtuse, n_failed = _channel_kernel(
        nl.start, np.ascontiguousarray(nl.separation), radii[nl.j], radii, float(eps))
    return xr.Dataset(
        data_vars=dict(ratio=("channel", ratio), particle=("channel", owner),
                       n_obtuse=((), int(n_obtuse)), n_failed=((), int(n_failed))),
        attrs=dict(eps=eps, definition="R / r_central, Apollonius circle externally tangent "
                                       "to three neighbour spheres in their plane"),
    )


def channel_histogram(channels: xr.Dataset, bin_width: float = 0.01,
                      ratio_max: float | None = None) -> xr.Dataset:
    """Normalised histogram (probability density) of R / r with the source's bin 0.01.

    Parameters
    ----------
    channels : xarray.Dataset
        Output of :func:`channel_radii` (its ``ratio`` variable is used).
    bin_width : float, default 0.01
        Width of the bins, starting at 0.
    ratio_max : float, optional
        Upper end of the bins; default the largest ratio.

    Returns
    -------
    xarray.Dataset
        ``density`` (integrates to 1) on the bin centres ``ratio_bin``; attributes
        ``bin_width`` and ``n_channels``.

    Raises
    ------
    InvalidInputError
        If there are no channels.
    """
    ratio = channels["ratio"].values
    if ratio.size == 0:
        raise InvalidInputError("no channels to histogram (no acute neighbour triangles)")
    top = float(ratio.max()) if ratio_max is None else float(ratio_max)
    edges = np.arange(0.0, top + bin_width, bin_width)
    hist, edges = np.histogram(ratio, bins=edges, density=True)
    return xr.Dataset(dict(density=("ratio_bin", hist)),
                      coords=dict(ratio_bin=0.5 * (edges[1:] + edges[:-1])),
                      attrs=dict(bin_width=bin_width, n_channels=int(ratio.size)))
