"""Periodic regular (weighted Delaunay) triangulation and the neighbour lists built on it.

The regular triangulation of spheres (centres x_i, weights r_i^2) is the dual of the power
(Laguerre) diagram; it is the lower convex hull of the lifted points (x_i, |x_i|^2 - r_i^2) in
d + 1 dimensions (Ogarko 2014, sec. 4.2, and the crystallinity of sec. 3.3.3
use it through CGAL; this is the same construction through scipy's ConvexHull / Qhull). With
equal radii it is the ordinary Delaunay triangulation.

Periodicity: the centres are replicated with every image that lies within a margin of the cell
(in fractional coordinates [-m_a, 1 + m_a]); the triangulation of the replicated set is correct
around the original particles if every simplex touching an original particle is certified:
its orthosphere (centre c, power w with |c - x_v|^2 - r_v^2 = w for its vertices) is empty in
the power sense, and any sphere with power distance below w lies within sqrt(w + r_max^2) of
c, so the simplex is exact when that ball lies inside the replicated region. Failing
simplices double the margin and the triangulation is recomputed.

Degenerate inputs (perfect lattices: more than d + 1 cospherical points) have no unique
triangulation; Qhull's triangulated output ('Qt') then splits the degenerate cells
arbitrarily (e.g. FCC octahedra get one diagonal, a neighbour at distance sqrt(2) a), and the
periodic copies of one cell may be split differently. The neighbour relation is therefore
symmetrised (j is a neighbour of i through image n iff i is one of j through -n); for
non-degenerate input this changes nothing. Use a distance cutoff for perfect crystals.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours import pairs_within


@dataclass(frozen=True)
class NeighbourList:
    """Directed neighbour list, sorted by i: j is a neighbour of i through image ``shift``;
    ``separation[k] = x_j + lattice @ shift[k] - x_i``. ``start`` is the CSR offset array
    (neighbours of i are entries start[i]:start[i+1]).

    Parameters
    ----------
    i, j : numpy.ndarray of int, shape (M,)
        The particle and its neighbour, sorted by (i, j); each bond appears in both directions.
    shift : numpy.ndarray of int, shape (M, d)
        Lattice image of j.
    separation : numpy.ndarray of float, shape (M, d)
        x_j + lattice @ shift - x_i (Cartesian).
    start : numpy.ndarray of int64, shape (N + 1,)
        CSR offsets; ``counts`` gives the neighbours per particle.
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    separation: np.ndarray
    start: np.ndarray

    @property
    def counts(self) -> np.ndarray:
        return np.diff(self.start)


def _finish(n, i, j, shift, x, lattice) -> NeighbourList:
    order = np.lexsort((j, i))
    i, j, shift = i[order], j[order], shift[order]
    sep = x[j] + shift @ lattice.T - x[i]
    start = np.searchsorted(i, np.arange(n + 1)).astype(np.int64)
    return NeighbourList(i=i, j=j, shift=shift, separation=sep, start=start)


def cutoff_neighbours(packing, cutoff: float = 1.2) -> NeighbourList:
    """Neighbours within ``cutoff`` times the contact distance r_i + r_j (all images).

    The default 1.2 includes the second BCC shell (2/sqrt(3) = 1.155) and excludes the second
    FCC/HCP/SC shell (sqrt 2), as in Steinhardt's lattice values; in jammed packings it sits
    near the first minimum of g2 at 1.25 D (Donev 2006, sec. 9.3.1.2).

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing.
    cutoff : float, default 1.2
        Range in units of the contact distance r_i + r_j; positive and finite.

    Returns
    -------
    NeighbourList
        Every pair within range in both directions, all periodic images.

    Raises
    ------
    InvalidInputError
        If the packing is not a periodic sphere packing or ``cutoff`` is not positive and
        finite.
    """
    packing.require_periodic_spheres("the structure analysis")
    if not np.isfinite(cutoff) or cutoff <= 0:
        raise InvalidInputError(f"cutoff must be a positive finite number, got {cutoff!r}")
    pairs = pairs_within(packing, rel_gap=cutoff - 1.0)
    i = np.concatenate([pairs.i, pairs.j])
    j = np.concatenate([pairs.j, pairs.i])
    shift = np.concatenate([pairs.shift, -pairs.shift])
    return _finish(packing.n_particles, i, j, shift, packing.fractional() @ packing.lattice.T,
                   packing.lattice)


def _replicate(s, margin):
    """Images of fractional points inside [-margin, 1 + margin]: (points, original, shift)."""
    d = s.shape[1]
    reach = np.ceil(margin).astype(int)
    pts, orig, shifts = [], [], []
    idx = np.arange(len(s))
    for n in itertools.product(*[range(-k, k + 1) for k in reach]):
        t = s + np.array(n)
        inside = np.all((t >= -margin) & (t <= 1 + margin), axis=1)
        pts.append(t[inside])
        orig.append(idx[inside])
        shifts.append(np.tile(np.array(n, dtype=np.int64), (int(inside.sum()), 1)))
    return np.concatenate(pts), np.concatenate(orig), np.concatenate(shifts).reshape(-1, d)


def regular_neighbours(packing, weighted: bool = True, margin: float | None = None,
                       max_tries: int = 4) -> NeighbourList:
    """Neighbours in the periodic regular triangulation (module docstring).

    ``weighted=False`` gives the ordinary Delaunay triangulation of the centres. ``margin`` is
    the initial replication depth in mean interparticle spacings (default 2), doubled until all
    simplices around the original particles are certified. Particles whose power cell is empty
    (possible for very unequal radii) have no neighbours.

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing, d >= 2.
    weighted : bool, default True
        Weights r_i^2 (regular, power-diagram dual) or none (Delaunay).
    margin : float, optional
        Initial replication depth in mean interparticle spacings; default 2 (2 (d + 1) when
        N < d + 1).
    max_tries : int, default 4
        Doublings of the margin before giving up.

    Returns
    -------
    NeighbourList
        The edges of the periodic triangulation at the original particles, both directions.

    Raises
    ------
    InvalidInputError
        If the packing is not a periodic sphere packing, d < 2, or the triangulation cannot be
        certified within ``max_tries`` margins (degenerate or far too sparse configuration).
    """
    packing.require_periodic_spheres("the structure analysis")
    n, d = packing.n_particles, packing.dim
    if d < 2:
        raise InvalidInputError("a triangulation needs d >= 2")
    if n < d + 1 and margin is None:
        margin = 2.0 * (d + 1)
    lat = packing.lattice
    s = packing.fractional()
    centre = lat @ np.full(d, 0.5)
    radii = packing.radii
    w2 = radii**2 if weighted else np.zeros(n)
    spacing = (packing.volume / n) ** (1.0 / d)
    m_abs = (2.0 if margin is None else float(margin)) * spacing
    for _ in range(max_tries):
        m_frac = m_abs / packing.heights
        t, orig, shift = _replicate(s, m_frac)
        x = t @ lat.T - centre
        lift = np.einsum("ij,ij->i", x, x) - w2[orig]
        scale = np.ptp(x) / max(np.ptp(lift), 1e-300)  # a positive rescaling keeps the lower hull
        hull = ConvexHull(np.column_stack([x, lift * scale]), qhull_options="Qt Qx" if d >= 4 else "Qt")
        lower = hull.equations[:, d] < 0
        simplices = hull.simplices[lower]
        home = np.all(shift == 0, axis=1)
        touching = home[simplices].any(axis=1)
        simplices = simplices[touching]
        if _certified(simplices, x, w2[orig], radii.max() ** 2 if weighted else 0.0, lat, m_frac):
            break
        m_abs *= 2.0
    else:
        raise InvalidInputError(
            f"the periodic regular triangulation could not be certified with a margin of "
            f"{m_abs / 2:.3g}; the configuration may be degenerate or far too sparse")
    # directed edges from original (home) vertices
    a_idx, b_idx = [], []
    for u, v in itertools.permutations(range(d + 1), 2):
        a_idx.append(simplices[:, u])
        b_idx.append(simplices[:, v])
    a, b = np.concatenate(a_idx), np.concatenate(b_idx)
    keep = home[a]
    a, b = a[keep], b[keep]
    fwd = np.column_stack([orig[a], orig[b], shift[b]])
    rev = np.column_stack([orig[b], orig[a], -shift[b]])
    key = np.unique(np.concatenate([fwd, rev]), axis=0)  # union: see the module docstring
    return _finish(n, key[:, 0], key[:, 1], key[:, 2:].astype(np.int64), s @ lat.T, lat)


def _certified(simplices, x, w, wmax, lat, m_frac) -> bool:
    """Every simplex's power ball lies inside the replicated region (module docstring).

    Flat simplices (zero volume, from splitting a degenerate cell) have no orthosphere of their
    own; they share it with the non-degenerate simplices of that cell and are skipped.
    """
    if len(simplices) == 0:
        return False
    p = x[simplices]  # (S, d+1, d)
    ws = w[simplices]
    a = 2.0 * (p[:, 1:] - p[:, :1])
    scale = np.abs(a).max(axis=(1, 2)) ** a.shape[1]
    solid = np.abs(np.linalg.det(a)) > 1e-10 * scale
    if not solid.any():
        return False
    p, ws, a = p[solid], ws[solid], a[solid]
    rhs = (np.einsum("skd,skd->sk", p[:, 1:], p[:, 1:]) - ws[:, 1:]
           - (np.einsum("sd,sd->s", p[:, 0], p[:, 0]) - ws[:, 0])[:, None])
    c = np.linalg.solve(a, rhs[..., None])[..., 0]
    power = np.einsum("sd,sd->s", c - p[:, 0], c - p[:, 0]) - ws[:, 0]
    reach = np.sqrt(np.maximum(power + wmax, 0.0))
    c_frac = np.linalg.solve(lat, (c + lat @ np.full(lat.shape[0], 0.5)).T).T
    heights = 1.0 / np.linalg.norm(np.linalg.inv(lat), axis=1)
    r_frac = reach[:, None] / heights[None, :]
    return bool(np.all((c_frac - r_frac >= -m_frac) & (c_frac + r_frac <= 1 + m_frac)))


def neighbour_list(packing, neighbours) -> NeighbourList:
    """Neighbours from a specification: "delaunay" (the regular triangulation), a cutoff in
    contact distances (a number, see :func:`cutoff_neighbours`), or a ready NeighbourList.

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing.
    neighbours : "delaunay", float or NeighbourList
        The specification; a NeighbourList is returned as given.

    Returns
    -------
    NeighbourList
        The neighbours.

    Raises
    ------
    InvalidInputError
        If ``neighbours`` is none of these, or as :func:`regular_neighbours` /
        :func:`cutoff_neighbours`.
    """
    if isinstance(neighbours, NeighbourList):
        return neighbours
    if isinstance(neighbours, str) and neighbours == "delaunay":
        return regular_neighbours(packing)
    if isinstance(neighbours, (int, float, np.floating, np.integer)) and not isinstance(neighbours, bool):
        return cutoff_neighbours(packing, float(neighbours))
    raise InvalidInputError(
        f"neighbours must be 'delaunay', a cutoff in contact distances (e.g. 1.2), or a "
        f"NeighbourList, got {neighbours!r}")
