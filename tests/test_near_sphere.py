"""Ellipses near the disk point (Donev 2006, sec. 5.9.2.1, Eqs. 5.27-5.29): the density slope s_phi
from the self-stress of a jammed disk packing."""

import numpy as np
import pytest

from hardpack import InvalidInputError, Packing
from hardpack.jamming import contact_network, self_stress, verify
from hardpack.jamming.near_sphere import ellipse_slope, slope_at_angles


@pytest.fixture(scope="module")
def loaded(jammed_disks):
    """(separation, i, j, forces, radii) of the backbone self-stress of the jammed 64-disk packing."""
    result = verify(jammed_disks)
    net, f = result.network, result.forces.forces
    return net.separation, net.i, net.j, f, jammed_disks.radii, result


def test_verify_reports_the_slope_of_its_self_stress(loaded):
    sep, i, j, f, radii, result = loaded
    assert result.ellipse_slope == ellipse_slope(sep, i, j, f, radii).slope
    assert result.to_dataset().attrs["ellipse_slope"] == result.ellipse_slope


def test_optimal_orientations_balance_torques_and_beat_any_other(loaded):
    """Eq. 5.27 is the stationarity of the density gain: at the Eq. 5.28 angles the two formulas of
    the slope agree, the torque sum_j F_ij sin 2(phi_i - theta_ij) vanishes, and no other
    assignment (random, aligned, or perturbed) does better."""
    sep, i, j, f, radii, _ = loaded
    best = ellipse_slope(sep, i, j, f, radii)
    assert slope_at_angles(sep, i, j, f, radii, best.angles) == pytest.approx(best.slope, abs=1e-12)
    theta = np.arctan2(sep[:, 1], sep[:, 0])
    phi = np.nan_to_num(best.angles)
    torque = np.zeros(len(radii))
    np.add.at(torque, i, f * np.sin(2 * (phi[i] - theta)))
    np.add.at(torque, j, f * np.sin(2 * (phi[j] - theta)))
    assert np.abs(torque).max() < 1e-9 * f.max()
    rng = np.random.default_rng(3)
    for _ in range(50):
        noisy = phi + rng.normal(0, 0.1, len(phi))
        assert slope_at_angles(sep, i, j, f, radii, noisy) < best.slope
    assert 0 < best.slope < 1


def test_random_orientations_gain_nothing_on_average(loaded):
    """Donev 2006, sec. 5.9.2: a random orientation assignment has zero expected density change
    (E sin^2 = 1/2); mean over 4000 draws within 4 standard errors of 0."""
    sep, i, j, f, radii, _ = loaded
    rng = np.random.default_rng(5)
    draws = np.array([slope_at_angles(sep, i, j, f, radii, rng.uniform(0, np.pi, len(radii)))
                      for _ in range(4000)])
    assert abs(draws.mean()) < 4 * draws.std(ddof=1) / np.sqrt(len(draws))


def test_aligned_orientations_give_the_stress_anisotropy(loaded):
    """A common orientation is an affine stretch: s = 2 e^T sigma e / tr sigma - 1, with e the
    shrunk axis and sigma = sum_c F_c (O_i + O_j) u u^T (exact identity)."""
    sep, i, j, f, radii, _ = loaded
    u = sep / np.linalg.norm(sep, axis=1)[:, None]
    sigma = np.einsum("c,ci,cj->ij", f * (radii[i] + radii[j]), u, u)
    for phi in (0.0, 0.4, 1.3):
        e = np.array([-np.sin(phi), np.cos(phi)])
        expected = 2 * e @ sigma @ e / np.trace(sigma) - 1
        got = slope_at_angles(sep, i, j, f, radii, np.full(len(radii), phi))
        assert got == pytest.approx(expected, abs=1e-12)


def test_triangular_crystal_gains_nothing():
    """Six equal contacts at 60 degrees: C_i = sum exp(2 i theta) = 0, so s_phi = 0 (the affine
    stretch of the densest disk packing is a densest ellipse packing)."""
    a = 1.0
    lattice = np.array([[4 * a, 2 * a], [0.0, 4 * a * np.sqrt(3) / 2]])
    frac = np.array([[x / 4, y / 4] for y in range(4) for x in range(4)])
    p = Packing(frac @ lattice.T, np.full(16, a / 2), lattice)
    net = contact_network(p, 1e-9)
    forces = self_stress(net, np.ones(16, bool))
    assert net.n_contacts == 48
    result = ellipse_slope(net.separation, net.i, net.j, forces.forces, p.radii)
    assert result.slope == pytest.approx(0.0, abs=1e-12)


def test_monodisperse_reduces_to_the_printed_formula():
    """For equal radii the derived slope is Donev's printed Eq. 5.29,
    2 sum_i sum_j f_ij sin^2(phi_i - theta_ij) / sum_i sum_j f_ij - 1."""
    rng = np.random.default_rng(0)
    m, n = 40, 12
    i, j = rng.integers(0, n, m), rng.integers(0, n, m)
    sep, f, phi = rng.normal(size=(m, 2)), rng.uniform(0.1, 2, m), rng.uniform(0, np.pi, n)
    theta = np.arctan2(sep[:, 1], sep[:, 0])
    printed = 2 * np.sum(f * (np.sin(phi[i] - theta) ** 2 + np.sin(phi[j] - theta) ** 2)) / (2 * f.sum()) - 1
    assert slope_at_angles(sep, i, j, f, np.full(n, 0.7), phi) == pytest.approx(printed, abs=1e-12)


@pytest.mark.parametrize("change, message", [
    (lambda a: {**a, "separation": a["separation"][:, :1]}, "shape"),
    (lambda a: {**a, "forces": -a["forces"]}, "non-negative"),
    (lambda a: {**a, "radii": a["radii"] * np.nan}, "finite"),
    (lambda a: {**a, "j": a["j"] + 100}, "indices"),
])
def test_bad_input_is_refused(change, message):
    args = dict(separation=np.ones((3, 2)), i=np.array([0, 1, 2]), j=np.array([1, 2, 0]),
                forces=np.ones(3), radii=np.ones(3))
    with pytest.raises(InvalidInputError, match=message):
        ellipse_slope(**change(args))
