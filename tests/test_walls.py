"""Hard walls and spherical containers in the sphere MD engine, RSA inside walls, and the container
analysis of Donev 2006, Ch. 7 (radial profile, Eq. 7.2 extrapolation, window fluctuations)."""

import numpy as np
import pytest

from hardpack.distributions import monodisperse
from hardpack.events.roots import container_time
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.boundaries import HardWalls, SphericalContainer
from hardpack.geometry.packing import Packing
from hardpack.initial import random_packing
from hardpack.md import StopCriteria, compress
from hardpack.md.engine import Engine
from hardpack.md.simulation import Simulation, maxwell_boltzmann
from hardpack.structure.containers import (
    ball_intersection_volume,
    extrapolate_bulk_density,
    radial_density_profile,
    window_fluctuations,
)


def one_sphere(x, v, a, box, boundary):
    return Engine(np.array([x], float), np.array([v], float), np.array([a], float), np.asarray(box, float),
                  boundary=boundary)


# ----------------------------------------------------------------------------- exact event times
def test_sphere_bouncing_between_two_walls_exact_times():
    """x0 = 5, v = 1, a = 0.5, walls at 0 and 10 on x: hits at t = 4.5, 13.5, 22.5, ...; at t = 20
    it has hit twice and sits at x = 0.5 + (20 - 13.5) = 7, each hit giving the wall 2 m v."""
    eng = one_sphere([5.0, 5, 5], [1.0, 0, 0], 0.5, [10, 10, 10], HardWalls((0,)))
    res = eng.run_window(0.0, 0.5, 10**9, 20.0)
    assert res.wall_collisions == 2
    np.testing.assert_allclose(eng.positions[0], [7.0, 5, 5], rtol=0, atol=1e-12)
    np.testing.assert_allclose(eng.velocities[0], [1.0, 0, 0], rtol=0, atol=0)
    np.testing.assert_allclose(res.wall_momentum, [4.0, 0, 0], rtol=1e-14)


def test_growing_sphere_hits_wall_at_exact_time():
    """a(t) = a0 (1 + kappa t): the upper wall is hit when x0 + v t = L - a(t), t* = (L - a0 - x0) /
    (v + a0 kappa); the reflection reverses the approach speed v + adot: v' = 2 adot - v... along -x:
    v' = v - 2 (v + adot) = -(v + 2 adot)."""
    a0, kappa, x0, v, L = 0.5, 0.1, 5.0, 1.0, 10.0
    t_hit = (L - a0 - x0) / (v + a0 * kappa)
    eng = one_sphere([x0, 5, 5], [v, 0, 0], a0, [L, L, L], HardWalls((0,)))
    res = eng.run_window(kappa, 0.5, 1, np.inf)  # the window ends at the first (wall) collision
    assert res.wall_collisions == 1
    assert res.duration == pytest.approx(t_hit, rel=1e-13)
    assert eng.velocities[0, 0] == pytest.approx(-(v + 2 * a0 * kappa), rel=1e-13)


def test_single_particle_in_spherical_container():
    """From the centre along x in a container of radius R = 3 (a = 0.5): hits at 2.5, 7.5, 12.5;
    on a chord the speed and the angular momentum about the centre are conserved, and every hit
    is at |x - c| = R - a."""
    eng = one_sphere([3.0, 3, 3], [1.0, 0, 0], 0.5, [6, 6, 6], SphericalContainer((3, 3, 3), 3.0))
    res = eng.run_window(0.0, 0.5, 10**9, 10.0)
    assert res.wall_collisions == 2
    np.testing.assert_allclose(eng.positions[0], [3.0 + 2.5 - 2.5, 3, 3], atol=1e-12)
    np.testing.assert_allclose(eng.velocities[0], [1.0, 0, 0], atol=1e-14)
    # an off-centre chord
    x0, v0 = np.array([3.4, 2.1, 3.3]), np.array([0.3, 0.8, -0.5])
    eng = one_sphere(x0, v0, 0.5, [6, 6, 6], SphericalContainer((3, 3, 3), 3.0))
    ang0 = np.cross(x0 - 3, v0)
    for _ in range(5):
        res = eng.run_window(0.0, 0.5, 1, np.inf)
        x, v = eng.positions[0], eng.velocities[0]
        assert np.linalg.norm(x - 3) == pytest.approx(2.5, rel=1e-13)
        assert np.linalg.norm(v) == pytest.approx(np.linalg.norm(v0), rel=1e-13)
        np.testing.assert_allclose(np.cross(x - 3, v), ang0, rtol=1e-12, atol=1e-13)


def test_container_time_after_reflection_is_the_next_hit():
    """Just reflected (on the wall, moving inward) the next hit is a full chord later, not t = 0
    (a sphere crossing the container centre from the wall: 2 (R - a) / |v|); growing: a sphere at
    rest at the centre hits when R - a0 = adot t."""
    rho = 2.5
    assert container_time(np.array([rho, 0, 0]), np.array([-1.0, 0, 0]), rho, 0.0) == pytest.approx(2 * rho)
    assert container_time(np.array([rho * (1 + 1e-16), 0, 0]), np.array([-1.0, 0, 0]), rho, 0.0) \
        == pytest.approx(2 * rho)
    # touching from inside by one ulp, moving inward: exit_root's form cancels to 0 here
    assert container_time(np.array([np.nextafter(rho, 0), 0, 0]), np.array([-1.0, 0, 0]), rho, 0.0) \
        == pytest.approx(2 * rho)
    assert container_time(np.array([rho, 0, 0]), np.array([1.0, 0, 0]), rho, 0.0) == 0.0
    assert container_time(np.zeros(3), np.zeros(3), rho, 0.1) == pytest.approx(rho / 0.1)


# ----------------------------------------------------------------------------- bookkeeping, pressure
def test_walls_conserve_energy_and_periodic_momentum():
    """Walls on x only: no growth, the kinetic energy is conserved and the momentum along the
    periodic axes y, z is conserved exactly (reflections change only v_x)."""
    pk = random_packing(60, 3, monodisperse(0.5), 0.3, seed=2, boundary="hard_walls", wall_axes=(0,))
    v = maxwell_boltzmann(60, 3, 4)
    sim = Simulation(pk, v, 0.0)
    ke0, p0 = 0.5 * (v**2).sum(), v.sum(axis=0)
    walls = 0
    for _ in range(10):
        rec = sim.run_window(600)
        walls += rec["wall_collisions"]
    v1 = sim.velocities()
    assert walls > 50
    assert 0.5 * (v1**2).sum() == pytest.approx(ke0, rel=1e-12)
    np.testing.assert_allclose(v1.sum(axis=0)[1:], p0[1:], atol=1e-11)
    final = sim.packing()
    assert final.boundary == pk.boundary
    assert final.containment_report().n_outside == 0 and final.overlap_report().n_overlapping == 0


def test_ideal_gas_pressure_on_walls():
    """A dilute gas (a = 0.05, phi = 5e-5, second virial term 4 phi = 2e-4) in a closed cube: each
    centre bounces along x between a and L - a, giving a wall of area L^2 the force
    m <v_x^2> / (L - 2a) = kT / (L - 2a), so p = N kT / (L^2 (L - 2a)) and
    Z_wall (L - 2a) / L = 1 within the standard error over windows (+ 1e-3)."""
    n, L, a = 100, 10.0, 0.05
    rng = np.random.default_rng(5)
    pk = Packing(a + rng.random((n, 3)) * (L - 2 * a), np.full(n, a), np.diag([L] * 3),
                 boundary=HardWalls((0, 1, 2)))
    sim = Simulation(pk, maxwell_boltzmann(n, 3, 6), 0.0)
    z = [sim.run_window(4 * n)["Z_wall"] for _ in range(40)]
    z = np.array(z) * (L - 2 * a) / L
    err = z.std(ddof=1) / np.sqrt(len(z))
    assert abs(z.mean() - 1.0) < 3 * err + 1e-3, (z.mean(), err)


def test_ls_compression_in_spherical_container_jams_inside():
    """LS growth inside a fixed spherical container: the end state is inside the wall, overlap free,
    with a jammed backbone (wall contacts count) and diverging pressure; phi below the bulk MRJ
    value (the wall layer is loose, Donev 2006, Ch. 7)."""
    pk = random_packing(150, 3, monodisperse(0.5), 0.2, seed=3, boundary="spherical_container")
    res = compress(pk, 0.05, 1, stop=StopCriteria(max_pressure=1e9))
    out = res.packing
    assert isinstance(out.boundary, SphericalContainer) and out.boundary == pk.boundary
    assert out.containment_report().n_outside == 0 and out.overlap_report().n_overlapping == 0
    assert res.stats["jamming_check"] == "passed"
    assert 0.5 < out.phi < 0.64


def test_rsa_inside_walls_and_container():
    for kind in ("spherical_container", "hard_walls"):
        pk = random_packing(200, 3, monodisperse(0.5), 0.25, seed=1, boundary=kind)
        assert pk.phi == pytest.approx(0.25)
        assert pk.containment_report().n_outside == 0 and pk.overlap_report().n_overlapping == 0
    pk = random_packing(200, 3, monodisperse(0.5), 0.25, seed=1, boundary="spherical_container")
    dist = np.linalg.norm(pk.positions - np.array(pk.boundary.centre), axis=1)
    # uniform in the reachable ball of radius R - a: mean of (r / rho)^3 is 1/2
    assert np.mean((dist / (pk.boundary.radius - 0.5)) ** 3) == pytest.approx(0.5, abs=4 * np.sqrt(1 / 12 / 200))


# ----------------------------------------------------------------------------- analysis (Ch. 7)
def test_ball_intersection_volume_by_hand():
    """d = 3: R = 2, a = 1, s = 2: pi (1)^2 (4 + 4 - 3 + 8 + 12 - 12) / 24 = 13 pi / 24; two unit
    disks at distance 1 overlap in 2 pi / 3 - sqrt(3) / 2; inside / outside limits."""
    assert ball_intersection_volume(2.0, 1.0, 2.0) == pytest.approx(13 * np.pi / 24, rel=1e-14)
    assert ball_intersection_volume(1.0, 1.0, 1.0, d=2) == pytest.approx(2 * np.pi / 3 - np.sqrt(3) / 2, rel=1e-14)
    assert ball_intersection_volume(2.0, 1.0, 0.5) == pytest.approx(4 * np.pi / 3)
    assert ball_intersection_volume(0.5, 1.0, 0.3) == pytest.approx(4 * np.pi / 3 * 0.125)
    assert ball_intersection_volume(2.0, 1.0, 3.0) == 0.0


def test_radial_profile_of_known_configuration():
    """One sphere (a = 1) at the container centre: phi = 1 in shells inside r = 1, 0 outside; a
    sphere at distance 2 from the centre covers 13 pi / 24 of the ball of radius 2 (core average
    at r = 2: (13 pi / 24) / (32 pi / 3))."""
    box = np.diag([8.0, 8, 8])
    pk = Packing(np.array([[4.0, 4, 4]]), np.array([1.0]), box, boundary=SphericalContainer((4, 4, 4), 4.0))
    prof = radial_density_profile(pk, n_shells=8)
    np.testing.assert_allclose(prof.phi.values, [1, 1, 0, 0, 0, 0, 0, 0], atol=1e-14)
    pk = Packing(np.array([[6.0, 4, 4]]), np.array([1.0]), box, boundary=SphericalContainer((4, 4, 4), 4.0))
    prof = radial_density_profile(pk, n_shells=4)
    assert prof.phi_core_average.values[1] == pytest.approx((13 * np.pi / 24) / (32 * np.pi / 3), rel=1e-13)
    # the shells add up to the sphere's volume
    shells = np.diff(ball_volume(np.linspace(0, 4, 5), 3))
    assert (prof.phi.values * shells).sum() == pytest.approx(4 * np.pi / 3, rel=1e-13)


def test_eq_7_2_expansion_and_extrapolation_on_synthetic_data():
    """Dphi(x) = A exp(-x): moments m_0 = A, m_1 = A, m_2 = 2 A, so Eq. 7.2 (with the moment indices
    derived in hardpack.structure.containers) gives phi_avg = phi0 - 3 A d + 6 A d^2 - 6 A d^3 up to
    exp(-1/d) terms; checked against direct integration of Eq. 7.1, then a linear fit over small d
    with noise recovers phi0 within its standard error."""
    phi0, A = 0.64, 0.3
    for delta in (0.02, 0.05, 0.1):
        r = np.linspace(0, 1, 200001)  # R = 1, a = delta
        phi_r = phi0 - A * np.exp(-(1 - r) / delta)
        integral = 3 * np.trapezoid(r**2 * phi_r, r)
        assert integral == pytest.approx(phi0 - 3 * A * delta + 6 * A * delta**2 - 6 * A * delta**3,
                                         abs=3 * A * np.exp(-1 / delta) + 1e-9)
    rng = np.random.default_rng(1)
    delta = np.linspace(0.02, 0.08, 12)
    noise = 0.002
    y = phi0 - 3 * A * delta + 6 * A * delta**2 - 6 * A * delta**3 + noise * rng.standard_normal(len(delta))
    fit = extrapolate_bulk_density(delta, y)
    bias = 6 * A * np.mean(delta**2)  # the quadratic term a straight line cannot follow, roughly
    assert abs(fit.phi0 - phi0) < 3 * fit.phi0_err + bias
    assert fit.slope == pytest.approx(-3 * A, rel=0.3)
    exact = extrapolate_bulk_density(delta, phi0 - 3 * A * delta)
    assert exact.phi0 == pytest.approx(phi0, abs=1e-13) and exact.slope == pytest.approx(-3 * A, rel=1e-12)


def test_window_fluctuations_mean_is_phi():
    """Windows placed uniformly: the mean covered fraction is phi exactly in expectation (within
    4 standard errors), and sigma_phi falls with R."""
    pk = random_packing(400, 3, monodisperse(0.5), 0.3, seed=4)
    out = window_fluctuations(pk, [1.0, 2.0], n_windows=400, seed=2)
    se = out.sigma_phi.values / np.sqrt(400)
    assert np.all(np.abs(out.phi_mean.values - pk.phi) < 4 * se)
    assert out.sigma_phi.values[1] < out.sigma_phi.values[0]


def test_a_single_sphere_in_a_container_compresses_to_a_target_phi():
    """N = 1 is valid with walls: the start velocity keeps its momentum (removing the mean of one
    particle left it at rest, with NaN speed after the kT scaling) and LS growth reaches phi."""
    v = maxwell_boltzmann(1, 3, 5)
    assert np.all(np.isfinite(v)) and np.einsum("ij,ij->", v, v) == pytest.approx(3.0)
    pk = Packing(np.array([[3.2, 2.9, 3.1]]), np.array([0.5]), np.eye(3) * 6.0,
                 boundary=SphericalContainer((3, 3, 3), 3.0))
    res = compress(pk, 0.05, 1, stop=StopCriteria(target_phi=0.1, max_pressure=None))
    assert res.packing.phi == pytest.approx(0.1, rel=1e-9)
    assert res.packing.containment_report().n_outside == 0
