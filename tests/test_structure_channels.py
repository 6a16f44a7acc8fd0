"""Regular triangulation and Ogarko's channel analysis (hardpack.structure.tessellation/channels)."""

import itertools
import math

import numpy as np
import pytest
from scipy.optimize import least_squares, linprog
from scipy.spatial import Delaunay

from hardpack.errors import InvalidInputError
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.structure.channels import (
    apollonius_radius,
    channel_histogram,
    channel_radii,
)
from hardpack.structure.tessellation import regular_neighbours


def gas(n, d, length, radii, seed=0):
    rng = np.random.default_rng(seed)
    radii = np.broadcast_to(np.asarray(radii, float), (n,))
    return Packing(rng.random((n, d)) * length, radii, np.eye(d) * length, allow_overlap=True)


def edges(nl):
    return {(a, b, *s) for a, b, s in zip(nl.i.tolist(), nl.j.tolist(), nl.shift.tolist())}


def test_unweighted_triangulation_matches_scipy_delaunay_of_the_replicated_cell():
    n, length = 200, 9.0
    p = gas(n, 3, length, 0.1, seed=3)
    nl = regular_neighbours(p, weighted=False)
    x = p.fractional() * length
    shifts = np.array(list(itertools.product((-1, 0, 1), repeat=3)))
    pts = np.concatenate([x + length * s for s in shifts])
    orig = np.tile(np.arange(n), len(shifts))
    img = np.repeat(shifts, n, axis=0)
    ref = set()
    for simplex in Delaunay(pts).simplices:
        for u, v in itertools.permutations(simplex, 2):
            if not img[u].any():
                ref.add((int(orig[u]), int(orig[v]), *img[v].tolist()))
    assert edges(nl) == ref
    assert 14 < nl.counts.mean() < 16.5  # Poisson-Delaunay: 15.54 neighbours on average


def test_weighted_neighbours_are_power_diagram_neighbours():
    """Independent check in 2D: i and j (image n) share a power-cell edge iff the LP
    max t s.t. pow_i(y) = pow_j(y), pow_i(y) + t <= pow_k(y) for all other k has t > 0."""
    rng = np.random.default_rng(4)
    length = 6.0
    p = gas(30, 2, length, rng.uniform(0.1, 0.6, 30), seed=5)
    nl = regular_neighbours(p)
    found = edges(nl)
    x = p.fractional() * length
    shifts = np.array(list(itertools.product(range(-2, 3), repeat=2)))
    pts = np.concatenate([x + length * s for s in shifts])
    w = np.tile(p.radii**2, len(shifts))
    orig = np.tile(np.arange(30), len(shifts))
    img = np.repeat(shifts, 30, axis=0)
    lift = np.einsum("ij,ij->i", pts, pts) - w
    home = np.flatnonzero(~img.any(axis=1))
    checked = 0
    for i in home[:8]:
        near = np.flatnonzero(np.linalg.norm(pts - pts[i], axis=1) < 3.0)
        for j in near:
            if j == i:
                continue
            others = np.setdiff1d(np.arange(len(pts)), [i, j])
            # pow_i(y) - pow_k(y) = -2 y.(x_i - x_k) + lift_i - lift_k
            a_ub = np.column_stack([-2 * (pts[i] - pts[others]), np.ones(len(others))])
            b_ub = lift[others] - lift[i]
            a_eq = np.array([[*(-2 * (pts[i] - pts[j])), 0.0]])
            b_eq = np.array([lift[j] - lift[i]])
            res = linprog([0, 0, -1], A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=b_eq,
                          bounds=[(None, None), (None, None), (None, 1.0)], method="highs")
            adjacent = res.status == 0 and -res.fun > 1e-9
            key = (int(orig[i]), int(orig[j]), *img[j].tolist())
            assert adjacent == (key in found), key
            checked += 1
    assert checked > 50


def test_apollonius_exact_values():
    s3 = math.sqrt(3)
    tri = (np.array([0.0, 0, 0]), np.array([2.0, 0, 0]), np.array([1.0, s3, 0]))
    assert abs(apollonius_radius(*tri, 1.0, 1.0, 1.0) - (2 / s3 - 1)) < 1e-14
    square = (np.array([0.0, 0, 0]), np.array([2.0, 0, 0]), np.array([0.0, 2.0, 0]))
    assert abs(apollonius_radius(*square, 1.0, 1.0, 1.0) - (math.sqrt(2) - 1)) < 1e-14
    # three neighbours touching the central sphere at 120 degrees in one plane: R = r
    ring = tuple(2 * np.array([math.cos(t), math.sin(t), 0.0]) for t in (0, 2 * np.pi / 3, 4 * np.pi / 3))
    assert abs(apollonius_radius(*ring, 1.0, 1.0, 1.0) - 1.0) < 1e-14
    obtuse = (np.array([0.0, 0, 0]), np.array([2.0, 0, 0]), np.array([3.0, 0.5, 0]))
    assert apollonius_radius(*obtuse, 1.0, 1.0, 1.0) == -1.0
    almost_right = (np.array([0.0, 0, 0]), np.array([2.0, 0, 0]), np.array([-1e-9, 2.0, 0]))
    assert apollonius_radius(*almost_right, 1.0, 1.0, 1.0) == -1.0


def test_apollonius_unequal_radii_solves_the_tangency_equations():
    """For random acute triangles with unequal radii the returned R admits an in-plane centre
    c with |c - p_k| = R + r_k for all three spheres (least squares from the centroid)."""
    rng = np.random.default_rng(2)
    checked = 0
    while checked < 40:
        p = rng.normal(size=(3, 3)) * 3
        r = rng.uniform(0.2, 1.0, 3)
        rad = apollonius_radius(p[0], p[1], p[2], r[0], r[1], r[2])
        if rad == -1.0:
            continue
        e1 = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
        e2 = p[2] - p[0] - ((p[2] - p[0]) @ e1) * e1
        e2 /= np.linalg.norm(e2)
        start = p.mean(axis=0) - p[0]

        def residual(z, p=p, r=r, e1=e1, e2=e2, rad=rad):
            c = p[0] + z[0] * e1 + z[1] * e2
            return [np.linalg.norm(c - p[k]) - rad - r[k] for k in range(3)]

        fit = least_squares(residual, [start @ e1, start @ e2], xtol=1e-15, ftol=1e-15)
        assert np.max(np.abs(fit.fun)) < 1e-7 * rad  # least-squares stops near 1e-9
        checked += 1


def test_fcc_channels_show_the_triangle_square_and_ring_values():
    ch = channel_radii(lattice_packing("fcc", 3), neighbours=1.2)
    values = np.unique(np.round(ch.ratio.values, 9))
    for expected in (2 / math.sqrt(3) - 1, math.sqrt(2) - 1, 1.0):
        assert np.min(np.abs(values - expected)) < 1e-9
    assert int(ch.n_failed) == 0
    assert ch.ratio.size + int(ch.n_obtuse) == 108 * math.comb(12, 3)


def test_gas_channel_distribution_matches_ogarko():
    """Ogarko 2014, Fig. 4.2: ideal gas at nu = 0.0014, acute triangles only:
    roughly Gaussian with mean ~15.9 and sigma ~4 (read off a figure: we allow 5 % on the
    mean and 15 % on sigma); non-acute triangles are excluded."""
    n, r, nu = 2000, 1.0, 0.0014
    length = (n * 4 / 3 * math.pi * r**3 / nu) ** (1 / 3)
    packing = gas(n, 3, length, r, seed=11)
    nl = regular_neighbours(packing)
    ch = channel_radii(packing, neighbours=nl)
    x = ch.ratio.values
    assert abs(x.mean() - 15.9) < 0.05 * 15.9
    assert abs(x.std() - 4.0) < 0.15 * 4.0
    skew = np.mean((x - x.mean()) ** 3) / x.std() ** 3
    assert abs(skew) < 0.3
    assert abs(np.mean(np.abs(x - x.mean()) < x.std()) - 0.683) < 0.03
    # with the non-acute triangles (eps -> 0) the distribution gets a wide upper tail
    everything = channel_radii(packing, neighbours=nl, eps=1e-9).ratio.values
    cut = x.mean() + 3 * x.std()
    assert np.mean(everything > cut) > 20 * max(np.mean(x > cut), 1e-4)
    hist = channel_histogram(ch)
    assert abs(float((hist.density * hist.attrs["bin_width"]).sum()) - 1) < 1e-9


def test_channel_input_checks():
    p = lattice_packing("fcc", 2)
    with pytest.raises(InvalidInputError):
        channel_radii(p, neighbours=1.2, eps=0.0)
    with pytest.raises(InvalidInputError):
        channel_radii(lattice_packing("hypercubic1", 5))
