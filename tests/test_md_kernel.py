"""Two-body analytics of the event-driven MD kernel: collision times with growth, neighbourhood
exit times, and post-collision velocities (the growth-corrected elastic law derived in
hardpack.md._kernel).

Every expected number below is derived by hand from straight-line motion and linearly growing
radii, independently of the kernel's quadratic formulas.
"""

import numpy as np
import pytest

from hardpack.events.roots import exit_time, pair_time
from hardpack.md.engine import Engine


def pt(r, u, sig0, g):
    return pair_time(np.asarray(r, float), np.asarray(u, float), float(sig0), float(g))


def test_head_on_collision_time_with_growth():
    # centres 3 apart closing at 2, contact distance 1 growing at 0.5: 3 - 2t = 1 + 0.5t
    assert pt([3, 0, 0], [-2, 0, 0], 1.0, 0.5) == pytest.approx(2.0 / 2.5, rel=1e-15)


def test_growth_alone_brings_resting_spheres_into_contact():
    # 2D, at rest, 1.5 apart, contact distance 1 growing at 0.25: t = 0.5 / 0.25
    assert pt([0, 1.5], [0, 0], 1.0, 0.25) == pytest.approx(2.0, rel=1e-15)


def test_growth_catches_separating_pair():
    # separating at 0.1 but contact distance grows at 0.5: 2 + 0.1 t = 1 + 0.5 t -> t = 2.5
    assert pt([2, 0, 0], [0.1, 0, 0], 1.0, 0.5) == pytest.approx(2.5, rel=1e-14)


def test_oblique_collision_time():
    # impact parameter 0.5, contact distance 1: (t - 5)^2 + 0.25 = 1 -> t = 5 - sqrt(0.75)
    assert pt([-5, 0.5, 0], [1, 0, 0], 1.0, 0.0) == pytest.approx(5 - np.sqrt(0.75), rel=1e-14)
    # impact parameter above the contact distance: no collision
    assert pt([-5, 1.2, 0], [1, 0, 0], 1.0, 0.0) == np.inf


def test_no_collision_when_separating_or_tangential():
    assert pt([2, 0, 0], [1, 0, 0], 1.0, 0.0) == np.inf
    assert pt([0, 2, 0], [1, 0, 0], 1.0, 0.0) == np.inf  # B = 0, passing sideways


def test_roundoff_overlap_rule():
    # overlapping by round-off (C < 0): collide now if approaching, never if separating
    assert pt([1 - 1e-14, 0], [-1, 0], 1.0, 0.0) == 0.0
    assert pt([1 - 1e-14, 0], [1, 0], 1.0, 0.0) == np.inf


@pytest.mark.parametrize(
    "dr, v, rrem, adot, expected",
    [
        ([0, 0, 0], [0.5, 0, 0], 0.2, 0.0, 0.4),  # moving only: 0.5 t = 0.2
        ([0, 0, 0], [0, 0, 0], 0.2, 0.1, 2.0),  # growing only: 0.1 t = 0.2
        ([0, 0, 0], [0, 0.3, 0], 0.2, 0.1, 0.5),  # both: 0.3 t = 0.2 - 0.1 t
        ([0.1, 0, 0], [-1, 0, 0], 0.2, 0.0, 0.3),  # 0.1 - t = -0.2 on the far side
        ([0, 0, 0], [0, 0, 0], 0.2, 0.0, np.inf),  # at rest, not growing: never
    ],
)
def test_exit_time(dr, v, rrem, adot, expected):
    t = exit_time(np.asarray(dr, float), np.asarray(v, float), rrem, adot)
    assert t == pytest.approx(expected, rel=1e-14)


def _two_spheres(x1, x2, v1, v2, radius=0.5, box=12.0):
    d = len(x1)
    return Engine(np.array([x1, x2], float), np.array([v1, v2], float), np.full(2, radius),
                  np.full(d, box))


@pytest.mark.parametrize("kappa", [0.0, 0.1])
def test_head_on_collision_velocities_and_time(kappa):
    # radii 0.5 (1 + kappa t); contact when 3 - 2t = 1 + kappa t  ->  t_c = 2 / (2 + kappa)
    eng = _two_spheres([4.0, 6, 6], [7.0, 6, 6], [1, 0, 0], [-1, 0, 0])
    res = eng.run_window(kappa, 0.3, 1, np.inf)
    g = 2 * 0.5 * kappa  # adot_i + adot_j
    assert res.collisions == 1
    assert res.duration == pytest.approx(2.0 / (2.0 + kappa), rel=1e-14)
    # v_n = n.(v_j - v_i) - g = -2 - g is reversed: v_i' = v_i + v_n n, v_j' = v_j - v_n n
    np.testing.assert_allclose(eng.velocities, [[-1 - g, 0, 0], [1 + g, 0, 0]], rtol=1e-14, atol=1e-15)
    # contact distance equals the grown diameter
    dist = np.linalg.norm(eng.positions[1] - eng.positions[0])
    assert dist == pytest.approx(eng.radii.sum(), rel=1e-14)
    # virial r.J = |r| |v_n| and kinetic energy gain -v_n g
    assert res.virial == pytest.approx(dist * (2 + g), rel=1e-14)
    assert res.ke_end - 1.0 == pytest.approx((2 + g) * g, rel=1e-12, abs=1e-15)


def test_oblique_collision_keeps_tangential_velocity_and_momentum():
    # sphere 2 at rest; sphere 1 hits it with impact parameter 0.6 (contact distance 1, no growth)
    eng = _two_spheres([3.0, 5.6], [6.0, 5.0], [1.0, 0.0], [0.0, 0.0])
    p0 = eng.velocities.sum(axis=0).copy()
    res = eng.run_window(0.0, 0.3, 1, np.inf)
    assert res.duration == pytest.approx(3.0 - 0.8, rel=1e-14)  # (3 - t)^2 + 0.36 = 1
    n = np.array([0.8, -0.6])  # unit vector from 1 to 2 at contact
    v1, v2 = eng.velocities
    # equal masses: normal components exchange, tangential ones stay
    np.testing.assert_allclose(v2, np.dot([1.0, 0.0], n) * n, atol=1e-14)
    np.testing.assert_allclose(v1, [1.0, 0.0] - np.dot([1.0, 0.0], n) * n, atol=1e-14)
    np.testing.assert_allclose(eng.velocities.sum(axis=0), p0, atol=1e-15)
    assert res.ke_end == pytest.approx(0.5, rel=1e-14)


def test_periodic_image_collision():
    # the pair meets across the periodic boundary: x = 0.6 moving left, x = 11.4 moving right
    eng = _two_spheres([0.6, 6, 6], [11.4, 6, 6], [-1, 0, 0], [1, 0, 0])
    res = eng.run_window(0.0, 0.3, 1, np.inf)
    assert res.duration == pytest.approx((1.2 - 1.0) / 2.0, rel=1e-12)
    np.testing.assert_allclose(eng.velocities[:, 0], [1.0, -1.0], rtol=1e-14)


@pytest.mark.parametrize("d, kappa, omega, n, phi, skin", [
    (2, 0.05, 1.0, 150, 0.25, 0.3), (3, 0.0, 1.0, 150, 0.25, 0.3), (3, 0.02, 10.0, 600, 0.25, 0.3),
    (3, 0.0, 1.0, 20, 0.15, 0.5), pytest.param(4, 0.02, 1.0, 150, 0.15, 0.3, marks=pytest.mark.slow),
    (5, 0.0, 1.0, 243, 0.12, 0.3)])
def test_neighbour_lists_match_brute_force_after_many_partial_updates(d, kappa, omega, n, phi, skin):
    """Invariants of the bounding-sphere lists (Donev sec. 2.9): every particle lies inside its
    bounding sphere, and i lists j (with the minimum-image shift) exactly when their bounding
    spheres overlap. Checked by brute force after windows full of partial updates; omega = 10
    (radii uniform in volume over a factor 10) puts the spheres on several grid levels. The box of
    n = 20 at phi = 0.15 (L = 4.1) is smaller than 2 (R_i + R_j) plus the moves of two bounding
    centres (R = 1, skin 0.5): a kept pair of neighbours changes periodic image without a wrap.
    In d = 5 (N = 243, L = 3.2 diameters) image codes reach 682, so old and new codes of a pair can
    differ by a multiple of 256 (a scratch mark narrower than the code missed such a change)."""
    from hardpack.distributions import monodisperse, uniform_volume
    from hardpack.initial import random_packing
    from hardpack.md.simulation import maxwell_boltzmann

    dist = monodisperse(0.5) if omega == 1.0 else uniform_volume(omega)
    packing = random_packing(n, d, dist, phi, seed=d)
    eng = Engine(packing.fractional() * np.diag(packing.lattice),
                 maxwell_boltzmann(n, d, 1), packing.radii, np.diag(packing.lattice))
    exits = 0
    for w in range(10):
        res = eng.run_window(kappa, skin, 300, np.inf, rebuild=(w == 0))
        exits += res.exits
        box = eng.box
        bc, br, x, a = eng.bs[:, :d], eng.bs[:, d], eng.positions, eng.radii
        assert np.all(np.linalg.norm(x - bc, axis=1) + a <= br * (1 + 1e-12))
        for i in range(eng.n):
            partners, shifts = eng.neighbours(i)
            listed = dict(zip(partners.tolist(), shifts))
            assert len(listed) == eng.nn[i]  # no duplicates
            sep = bc - bc[i]
            shift = -np.round(sep / box)
            dist = np.linalg.norm(sep + shift * box, axis=1)
            expected = {j for j in np.flatnonzero(dist < br[i] + br) if j != i}
            assert set(listed) == expected
            codes = eng.nb[i, : eng.nn[i]].astype(np.int64) & ((1 << 2 * d) - 1)
            np.testing.assert_allclose(eng.imgvec[codes], shifts * box)
            for j, nvec in listed.items():
                np.testing.assert_array_equal(nvec, shift[j])
    assert exits > 50  # the windows really exercised partial updates
    assert (eng.ncl.shape[0] > 1) == (omega > 1.0)  # several grid levels only for wide sizes
