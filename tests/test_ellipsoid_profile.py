"""The radial density profile phi(r) of ellipsoids in a spherical container (Donev 2006,
Sec. 7.3.1.2, Fig. 7.5) from exact ellipsoid-ball intersection volumes:
:func:`hardpack.structure.containers.ellipsoid_radial_density_profile`.

Proofs: spheres given as ellipsoids equal the exact sphere profile; an independent Monte Carlo
estimate (uniform points in the ellipsoids counted in shells) within 4 standard errors in every
shell and every core ball, where the tangent-plane approximation of the text's footnote is refused;
the profile's integral over the ball equal to the packing's phi to round-off."""

import numpy as np
import pytest

from hardpack.distributions import monodisperse
from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.boundaries import SphericalContainer
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.initial import random_ellipsoid_packing, random_packing
from hardpack.md import StopCriteria, compress
from hardpack.structure.containers import (
    core_density,
    ellipsoid_radial_density_profile,
    radial_density_profile,
)

OLLIPSOID = [1.25, 1.0, 0.8]


def _identity_orientations(n, d):
    return np.zeros(n) if d == 2 else np.tile([1.0, 0, 0, 0], (n, 1))


def _as_ellipsoids(packing):
    """The sphere packing's spheres as ellipsoids with equal semiaxes."""
    n, d = packing.n_particles, packing.dim
    shape = Ellipsoids(np.repeat(packing.radii[:, None], d, axis=1), _identity_orientations(n, d))
    return Packing(packing.positions, lattice=packing.lattice, shape=shape, boundary=packing.boundary,
                   allow_overlap=True)


def _container(positions, semiaxes, orientations, radius):
    d = positions.shape[1]
    return Packing(positions + radius, lattice=2 * radius * np.eye(d), shape=Ellipsoids(semiaxes, orientations),
                   boundary=SphericalContainer((radius,) * d, radius), allow_overlap=True)


@pytest.fixture(scope="module")
def jammed_spheres():
    """200 equal spheres jammed in a spherical container (a/R = 0.14)."""
    start = random_packing(200, 3, monodisperse(1.0), 0.2, seed=1, boundary="spherical_container")
    return compress(start, 0.02, 1, stop=StopCriteria(max_pressure=1e9), final_growth_rate=0.01,
                    switch_pressure=1e3).packing


# ----------------------------------------------------------------------------- (a) spheres as ellipsoids
def test_spheres_as_ellipsoids_against_the_exact_profile(jammed_spheres):
    """Spheres given as ellipsoids: the profile and its core average equal the exact sphere
    profile (lens volumes) in every shell of 0.1 a, also at the centre where the tangent plane
    failed, and the core density equals the exact sphere core density."""
    p = jammed_spheres
    a, radius = p.radii.mean(), p.boundary.radius
    n_shells = int(np.ceil(radius / (0.1 * a)))
    exact = radial_density_profile(p, n_shells)
    prof = ellipsoid_radial_density_profile(_as_ellipsoids(p), n_shells)
    np.testing.assert_array_equal(prof["r"].values, exact["r"].values)
    assert prof.attrs["a"] == pytest.approx(a, rel=1e-15) and prof.attrs["method"] == "exact"
    shell = np.diff(ball_volume(np.append(prof["r_inner"].values, radius), 3))
    # each shell's covered volume to 1e-10 of a particle's volume per particle crossing it
    np.testing.assert_allclose(prof["phi"].values, exact["phi"].values, atol=1e-8 * ball_volume(a, 3) / shell.min())
    np.testing.assert_allclose(prof["phi_core_average"].values, exact["phi_core_average"].values, rtol=1e-9, atol=1e-9)
    for margin in (1.0, 3.0):
        assert core_density(_as_ellipsoids(p), margin) == pytest.approx(core_density(p, margin), abs=1e-9)


def test_a_centred_sphere_is_exact():
    """One sphere of radius a at the container centre: phi = 1 for r < a and 0 beyond."""
    p = _container(np.zeros((1, 3)), np.full((1, 3), 1.0), _identity_orientations(1, 3), 4.0)
    prof = ellipsoid_radial_density_profile(p, 40)
    r_out = prof["r_outer"].values
    np.testing.assert_allclose(prof["phi"].values[r_out <= 1.0], 1.0, atol=1e-12)
    np.testing.assert_allclose(prof["phi"].values[prof["r_inner"].values >= 1.0], 0.0, atol=1e-12)


# ----------------------------------------------------------------------------- (b) Monte Carlo
def _monte_carlo_profile(packing, edges, points_per_particle, seed):
    """Covered volume of each shell and its standard error from uniform random points in each
    particle (the unit ball's points mapped by x = c + Q^T O y): a particle of volume V puts
    V k / M in a shell holding k of its M points."""
    rng = np.random.default_rng(seed)
    d = packing.dim
    shape = packing.shape
    rot = shape.rotations()
    centre = np.asarray(packing.boundary.centre)
    volumes = shape.volumes(d)
    covered = np.zeros(len(edges) - 1)
    variance = np.zeros(len(edges) - 1)
    m = points_per_particle
    for i in range(packing.n_particles):
        y = rng.standard_normal((m, d))
        y *= (rng.random(m) ** (1 / d) / np.linalg.norm(y, axis=1))[:, None]
        x = packing.positions[i] + (y * shape.semiaxes[i]) @ rot[i]
        counts = np.histogram(np.linalg.norm(x - centre, axis=1), bins=edges)[0]
        frac = counts / m
        covered += volumes[i] * frac
        variance += volumes[i] ** 2 * frac * (1 - frac) / m
    return covered, np.sqrt(variance)


@pytest.mark.parametrize("d", [3, 2])
def test_profile_of_a_random_packing_against_monte_carlo(d):
    """A random start of ollipsoids (ellipses 1.25 : 0.8) in a container, shells of a / 2: the
    profile agrees with the Monte Carlo profile within 4 standard errors in every shell, and the
    covered volume of every ball r about the centre (the core average) as well."""
    axes = OLLIPSOID if d == 3 else [1.25, 0.8]
    p = random_ellipsoid_packing(60, axes, 0.1, 4, boundary="spherical_container")
    a = float(np.prod(axes) ** (1 / d))
    n_shells = int(np.ceil(p.boundary.radius / (0.5 * a)))
    prof = ellipsoid_radial_density_profile(p, n_shells)
    edges = np.append(prof["r_inner"].values, prof["r_outer"].values[-1])
    covered, se = _monte_carlo_profile(p, edges, 20_000, seed=5)
    shell = np.diff(ball_volume(edges, d))
    assert (np.abs(prof["phi"].values * shell - covered) <= 4 * se).all()
    inside, inside_se = np.cumsum(covered), np.sqrt(np.cumsum(se**2))
    ball = ball_volume(edges[1:], d)
    assert (np.abs(prof["phi_core_average"].values * ball - inside) <= 4 * inside_se).all()


def test_core_density_has_no_bias_where_the_tangent_plane_had_one():
    """Donev's tangent-plane value overcounts a uniform core of radius r by about (3/5) phi (a/r)^2
    of its volume; with 1e5 Monte Carlo points per particle that bias is many standard errors
    at r = 2a to 3a, and the exact core density agrees with Monte Carlo within 4."""
    p = random_ellipsoid_packing(150, OLLIPSOID, 0.12, 3, boundary="spherical_container")
    a = float(np.prod(OLLIPSOID) ** (1 / 3))
    radius = p.boundary.radius
    for core_radius in (2 * a, 3 * a):
        margin = (radius - core_radius) / a
        covered, se = _monte_carlo_profile(p, np.array([0.0, core_radius]), 100_000, seed=8)
        ball = ball_volume(core_radius, 3)
        phi, phi_se = covered[0] / ball, se[0] / ball
        assert abs(core_density(p, margin) - phi) <= 4 * phi_se
        assert 0.6 * p.phi * (a / core_radius) ** 2 > 5 * phi_se


def test_far_ellipsoids_against_monte_carlo_per_shell():
    """Six random ellipsoids (random orientations, semiaxes 0.5-2) about 40 particle sizes from the
    centre, shells of 0.2: the profile matches Monte Carlo within 4 standard errors in every shell,
    and the same comparison refuses a profile that ignores the shapes (the particles replaced by
    spheres of their volume)."""
    rng = np.random.default_rng(11)
    n = 6
    semiaxes = rng.uniform(0.5, 2.0, (n, 3))
    quat = rng.standard_normal((n, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    direction = rng.standard_normal((n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    positions = direction * rng.uniform(40.0, 45.0, (n, 1))
    p = _container(positions, semiaxes, quat, 50.0)
    prof = ellipsoid_radial_density_profile(p, 250)
    edges = np.append(prof["r_inner"].values, prof["r_outer"].values[-1])
    covered, se = _monte_carlo_profile(p, edges, 100_000, seed=3)
    shell = np.diff(ball_volume(edges, 3))
    exact = prof["phi"].values * shell
    assert (np.abs(exact - covered) <= 4 * se).all()
    assert exact.sum() == pytest.approx(p.shape.volumes(3).sum(), rel=1e-13)
    wrong = Ellipsoids(np.repeat(np.prod(semiaxes, axis=1)[:, None] ** (1 / 3), 3, axis=1), quat)
    q = Packing(p.positions, lattice=p.lattice, shape=wrong, boundary=p.boundary, allow_overlap=True)
    wrong_profile = ellipsoid_radial_density_profile(q, 250)["phi"].values * shell
    assert (np.abs(wrong_profile - covered) > 4 * se).any()


# ----------------------------------------------------------------------------- (c) the integral
@pytest.mark.parametrize("d", [3, 2])
def test_integral_over_the_container_is_the_packing_fraction(d):
    """3 R^-3 int_0^R r^2 phi dr (sum of phi times the shell volumes over the ball's) equals the
    packing's phi to round-off: every particle is wholly inside the ball r = R (classified exactly
    by its farthest point) and the covered volume at r = 0 is zero; so does the last core average."""
    axes = OLLIPSOID if d == 3 else [1.25, 0.8]
    p = random_ellipsoid_packing(80, axes, 0.1, 2, boundary="spherical_container")
    for n_shells in (1, 7, 300):
        prof = ellipsoid_radial_density_profile(p, n_shells)
        edges = np.append(prof["r_inner"].values, prof["r_outer"].values[-1])
        total = float(np.sum(prof["phi"].values * np.diff(edges**d))) / p.boundary.radius**d
        assert total == pytest.approx(p.phi, rel=1e-13)
        assert prof["phi_core_average"].values[-1] == pytest.approx(p.phi, rel=1e-13)
        assert (prof["phi"].values >= -1e-15).all()


def test_integral_of_jammed_spheres_matches_both_profiles(jammed_spheres):
    p = jammed_spheres
    as_ellipsoids = ellipsoid_radial_density_profile(_as_ellipsoids(p), 173)
    exact = radial_density_profile(p, 173)
    for prof in (as_ellipsoids, exact):
        assert prof["phi_core_average"].values[-1] == pytest.approx(p.phi, rel=1e-13)


# ----------------------------------------------------------------------------- the core density
def test_core_density_of_ellipsoids_is_the_profile_core_average():
    """core_density of ellipsoids is the covered fraction of the ball R - margin a, equal to the
    profile's core average at that radius."""
    p = random_ellipsoid_packing(80, OLLIPSOID, 0.1, 2, boundary="spherical_container")
    a = float(np.prod(OLLIPSOID) ** (1 / 3))
    radius = p.boundary.radius
    margin = radius / a / 2  # the ball of radius R / 2: the outer edge of shell 50 of 100
    prof = ellipsoid_radial_density_profile(p, 100)
    assert core_density(p, margin) == pytest.approx(float(prof["phi_core_average"].values[49]), rel=1e-12)
    with pytest.raises(InvalidInputError, match="core"):
        core_density(p, radius / a + 1)


# ----------------------------------------------------------------------------- refusals
def test_refuses_what_is_not_ellipsoids_in_a_container(jammed_spheres):
    with pytest.raises(InvalidInputError, match="exact radial_density_profile"):
        ellipsoid_radial_density_profile(jammed_spheres)
    periodic = random_ellipsoid_packing(10, OLLIPSOID, 0.1, 1)
    with pytest.raises(InvalidInputError, match="spherical container"):
        ellipsoid_radial_density_profile(periodic)
    p = random_ellipsoid_packing(10, OLLIPSOID, 0.1, 1, boundary="spherical_container")
    for bad in (0, 2.5, float("nan"), float("inf"), -3):
        with pytest.raises(InvalidInputError, match="n_shells"):
            ellipsoid_radial_density_profile(p, bad)


# ----------------------------------------------------------------------------- summary and figure
def _profiled(n, seed, margin=1.0):
    p = random_ellipsoid_packing(n, OLLIPSOID, 0.1, seed, boundary="spherical_container")
    prof = ellipsoid_radial_density_profile(p, 60)
    prof.attrs.update(N=n, seed=seed, phi_core=core_density(p, margin), core_margin=margin, shape_name="ollipsoid",
                      phi=p.phi, a_over_R=prof.attrs["a"] / p.boundary.radius)
    return p, prof


def test_ellipsoid_summary_keeps_each_packings_core_and_wall_layer():
    from hardpack.structure.containers import ellipsoid_container_summary, wall_layer_density

    made = [_profiled(n, s) for n, s in ((30, 2), (20, 1), (30, 1))]
    packings, profiles = [m[0] for m in made], [m[1] for m in made]
    ds = ellipsoid_container_summary(packings, [2, 1, 1], profiles=profiles)
    assert ds["N"].values.tolist() == [20, 30, 30] and ds["seed"].values.tolist() == [1, 1, 2]
    assert ds["phi_core"].values.tolist() == [profiles[k].attrs["phi_core"] for k in (1, 2, 0)]
    assert ds["phi_wall_layer"].values[0] == wall_layer_density(profiles[1])
    assert ds.attrs["core_margin"] == 1.0
    assert "phi_core" not in ellipsoid_container_summary(packings, [2, 1, 1])
    with pytest.raises(InvalidInputError, match="packings' order"):
        ellipsoid_container_summary(packings, [2, 1, 1], profiles=profiles[::-1])
    with pytest.raises(InvalidInputError, match="one radial profile per packing"):
        ellipsoid_container_summary(packings, [2, 1, 1], profiles=profiles[:2])
    profiles[0].attrs.pop("phi_core")
    with pytest.raises(InvalidInputError, match="phi_core"):
        ellipsoid_container_summary(packings, [2, 1, 1], profiles=profiles)


def test_ellipsoid_profile_figure_has_a_panel_per_shape(tmp_path):
    from hardpack.plots.containers import plot_ellipsoid_radial_profiles, plot_radial_profile
    from hardpack.plots.style import save

    _, olli = _profiled(30, 1)
    _, mm = _profiled(30, 2)
    mm.attrs["shape_name"] = "mm"
    fig = plot_ellipsoid_radial_profiles([mm, olli])
    assert [ax.get_title() for ax in fig.axes] == ["M&M", "ollipsoid"]
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("0.700" in t for t in labels) and any("core average" in t for t in labels)
    save(fig, tmp_path / "profile.pdf", tmp_path / "profile.png")
    assert (tmp_path / "profile.png").stat().st_size > 1000
    # the sphere figure reads the same variables
    save(plot_radial_profile([mm, olli]), tmp_path / "as_spheres.png")
    assert (tmp_path / "as_spheres.png").stat().st_size > 1000
