"""Ellipsoids and ellipses in a hard spherical container: the wall events of the ellipsoid MD
(:func:`hardpack.md._ellipsoid_kernel.wall_predict`, :func:`~hardpack.md._ellipsoid_kernel.wall_collide`;
Donev 2006, Ch. 7 and sec. 3.5).

- A single rotating ellipsoid (and ellipse) bouncing ~10^3 times: kinetic energy (translational
  plus rotational) and the angular momentum about the container centre (the wall force is radial)
  are conserved to round-off, and the exact gap (:mod:`hardpack.geometry.ellipsoid_container`)
  never goes below round-off. A wrong torque sign or lever arm breaks the angular momentum.
- A sphere-shaped ellipsoid reproduces the wall collision times of the sphere kernel
  (:func:`hardpack.events.roots.container_root`), without and with growth.
- An ideal gas of small ellipsoids: the wall pressure is N kT / V up to the finite size of the
  particles (between R/(R - a_min) and R/(R - a_max)) and the statistical error.
"""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.geometry.boundaries import SphericalContainer
from hardpack.geometry.ellipsoid_container import container_gaps
from hardpack.geometry.shapes import Ellipsoids
from hardpack.md.ellipsoid_engine import EllipsoidEngine, moments_of_inertia
from hardpack.md.engine import Engine


def _orient(rng, n, d):
    if d == 2:
        return rng.uniform(0, 2 * np.pi, n)
    q = rng.standard_normal((n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _angular_momentum(eng, centre):
    x = eng.positions - centre
    v = eng.velocities
    w = eng.angular_velocities
    inertia = eng.inertia
    if eng.d == 2:
        return float((x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]).sum() + (inertia * w).sum())
    return np.cross(x, v).sum(axis=0) + (inertia[:, None] * w).sum(axis=0)


def _gaps(eng, cont):
    shape = Ellipsoids(eng.semiaxes.copy(), eng.orientations.copy())
    return container_gaps(eng.positions, shape, cont.centre, cont.radius)[0]


@pytest.mark.parametrize("d", [3, 2])
def test_a_single_ellipsoid_bounces_conserving_energy_and_angular_momentum(d):
    rng = np.random.default_rng(4 + d)
    centre = np.full(d, 5.0)
    cont = SphericalContainer(tuple(centre), 4.0)
    axes = np.array([[1.0, 0.6, 0.3][:d]])
    nw = 3 if d == 3 else 1
    w = rng.standard_normal((1, nw)) * 3
    eng = EllipsoidEngine(centre[None] + 0.3, rng.standard_normal((1, d)), axes, _orient(rng, 1, d),
                          w if d == 3 else w[:, 0], 10 * np.ones(d), boundary=cont)
    e0 = sum(eng.energies())
    l0 = _angular_momentum(eng, centre)
    bounces = 0
    worst = np.inf
    for _ in range(40):
        res = eng.run_window(0.0, 0.5, 25, 1e9)
        bounces += res.wall_collisions
        worst = min(worst, _gaps(eng, cont).min())
    assert bounces == 1000
    assert sum(eng.energies()) == pytest.approx(e0, rel=1e-10)
    assert np.allclose(_angular_momentum(eng, centre), l0, rtol=0, atol=1e-9 * (1 + np.abs(l0).max()))
    assert worst > -1e-12 * cont.radius
    # the rotation exchanged energy with the translation (the lever arm is not radial)
    assert eng.energies()[1] != pytest.approx(0.5 * (w**2).sum() * moments_of_inertia(axes)[0], rel=1e-3)


@pytest.mark.parametrize("kappa", [0.0, 0.02])
def test_a_sphere_shaped_ellipsoid_hits_the_wall_when_the_sphere_kernel_says(kappa):
    rng = np.random.default_rng(9)
    d = 3
    centre = np.full(d, 5.0)
    cont = SphericalContainer(tuple(centre), 4.0)
    x0 = centre + rng.uniform(-1, 1, d)
    v0 = rng.standard_normal(d)
    r = 0.5
    ell = EllipsoidEngine(x0[None], v0[None], np.full((1, d), r), _orient(rng, 1, d),
                          rng.standard_normal((1, 3)), 10 * np.ones(d), boundary=cont)
    sph = Engine(x0[None].copy(), v0[None].copy(), np.array([r]), 10 * np.ones(d), boundary=cont)
    for _ in range(30):
        a = ell.run_window(kappa, 0.3, 1, 1e9)
        b = sph.run_window(kappa, 0.3, 1, 1e9)
        assert a.wall_collisions == b.wall_collisions == 1
        assert a.duration == pytest.approx(b.duration, rel=1e-11, abs=1e-13)
        assert np.allclose(ell.positions, sph.positions, rtol=0, atol=1e-10)
        assert np.allclose(ell.velocities, sph.velocities, rtol=0, atol=1e-10)
        assert a.wall_momentum[0] == pytest.approx(b.wall_momentum[0], rel=1e-10)


def test_an_ideal_gas_of_small_ellipsoids_presses_the_wall_with_n_kt_over_v():
    rng = np.random.default_rng(2)
    d, n = 3, 40
    centre = np.full(d, 1.0)
    cont = SphericalContainer(tuple(centre), 1.0)
    axes = np.tile([0.004, 0.003, 0.002], (n, 1))
    u = rng.standard_normal((n, d))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    pos = centre + u * 0.95 * rng.uniform(0, 1, (n, 1)) ** (1 / 3)
    inertia = moments_of_inertia(axes)
    eng = EllipsoidEngine(pos, rng.standard_normal((n, d)), axes, _orient(rng, n, d),
                          rng.standard_normal((n, 3)) / np.sqrt(inertia)[:, None], 2 * np.ones(d),
                          boundary=cont)
    area = 4 * np.pi * cont.radius**2
    volume = 4 / 3 * np.pi * cont.radius**3
    ratios = []
    for _ in range(40):
        res = eng.run_window(0.0, 0.05, 50 * n, 1e9)
        kt = 2 * res.ke_integral / (d * n * res.duration)  # translational kT, time averaged
        ratios.append(res.wall_momentum[0] / (area * res.duration) * volume / (n * kt))
    ratios = np.array(ratios)
    mean, se = ratios.mean(), ratios.std(ddof=1) / np.sqrt(len(ratios))
    lo, hi = cont.radius / (cont.radius - axes.min()), cont.radius / (cont.radius - axes.max())
    assert lo - 4 * se <= mean <= hi + 4 * se, (mean, se, lo, hi)
    assert se < 0.01


# ---------------------------------------------------------------- start, compression, storage, CLI
def test_container_start_is_seeded_inside_and_refuses_impossible_requests():
    from hardpack.errors import InvalidInputError
    from hardpack.initial import random_ellipsoid_packing

    for d, axes in ((3, [1.0, 1.0, 1 / 1.9]), (2, [1.0, 0.5])):
        p = random_ellipsoid_packing(30, axes, 0.1, 3, boundary="spherical_container")
        assert p.boundary.kind == "spherical_container" and p.phi == pytest.approx(0.1)
        assert p.containment_report().n_outside == 0 and p.overlap_report().n_overlapping == 0
        q = random_ellipsoid_packing(30, axes, 0.1, 3, boundary="spherical_container")
        assert np.array_equal(p.positions, q.positions)
        assert np.array_equal(p.shape.orientations, q.shape.orientations)
    with pytest.raises(InvalidInputError, match="lower phi"):
        random_ellipsoid_packing(30, [1.0, 1.0, 0.2], 0.3, 3, boundary="spherical_container", max_trials=200)
    with pytest.raises(InvalidInputError, match="'periodic', 'hard_walls' or 'spherical_container'"):
        random_ellipsoid_packing(3, [1.0, 0.5], 0.1, 3, boundary="slit")


@pytest.mark.parametrize("d", [3, 2])
def test_compression_in_a_container_jams_inside_and_round_trips(tmp_path, d):
    from hardpack.initial import random_ellipsoid_packing
    from hardpack.io import load_packing
    from hardpack.md import StopCriteria
    from hardpack.md.ellipsoid import compress_ellipsoids

    axes = [1.0, 1.0, 1 / 1.9] if d == 3 else [1.0, 0.5]
    p = random_ellipsoid_packing(30, axes, 0.1, 5, boundary="spherical_container")
    res = compress_ellipsoids(p, 0.1, 1, stop=StopCriteria(max_pressure=1e6), final_growth_rate=0.01,
                              switch_pressure=100)
    final = res.packing
    assert str(final.boundary) == str(p.boundary)
    assert res.stats["containment_check"] == "passed" and res.stats["max_wall_overlap"] <= 1e-9
    assert res.stats["Z"] >= 1e6 and res.stats["phi"] > (0.55 if d == 3 else 0.7)
    assert np.nanmax(res.timeseries["wall_collisions"].values) > 0
    # the jammed packing touches the wall: the smallest gap is far below the particle size
    gap = container_gaps(final.positions, final.shape, final.boundary.centre, final.boundary.radius)[0]
    assert -1e-9 < gap.min() / final.shape.bounding_radii.max() < 1e-4
    res.save(tmp_path / "j.nc")
    back = load_packing(tmp_path / "j.nc")
    assert np.array_equal(back.positions, final.positions) and str(back.boundary) == str(final.boundary)


def test_cli_init_and_compress_ellipsoids_in_a_container(tmp_path):
    from hardpack.cli import main
    from hardpack.io import load_packing

    start, out = tmp_path / "s.nc", tmp_path / "j.nc"
    assert main(["init", "--n", "24", "--d", "3", "--phi", "0.1", "--seed", "2", "--semiaxes", "1", "1",
                 str(1 / 1.9), "--boundary", "spherical_container", "--out", str(start)]) == 0
    p = load_packing(start)
    assert p.shape.kind == "ellipsoid" and p.boundary.kind == "spherical_container"
    assert main(["compress", "--init", str(start), "--out", str(out), "--growth-rate", "0.1",
                 "--max-pressure", "1e5", "--seed", "1"]) == 0
    jammed = load_packing(out)
    assert str(jammed.boundary) == str(p.boundary) and jammed.containment_report().n_outside == 0


def test_a_packing_crossing_the_wall_is_refused_by_the_engine():
    from hardpack.errors import InvalidInputError
    from hardpack.geometry.packing import Packing
    from hardpack.md import StopCriteria
    from hardpack.md.ellipsoid import compress_ellipsoids

    shape = Ellipsoids([[1.0, 0.5, 0.5]], [[1, 0, 0, 0]])
    cont = SphericalContainer((5, 5, 5), 3.0)
    bad = Packing([[7.2, 5, 5]], lattice=10 * np.eye(3), shape=shape, boundary=cont, allow_overlap=True)
    with pytest.raises(InvalidInputError, match="crosses the container wall"):
        compress_ellipsoids(bad, 0.1, 1)
    # one particle (no pairs: the pair virial stays 1, so the run stops at a target phi); it
    # gets velocities without a mean removed (which would leave it at rest)
    ok = bad.replace(positions=[[5, 5, 7.4]])  # extent 0.5 along z: inside
    res = compress_ellipsoids(ok, 0.1, 1, stop=StopCriteria(max_pressure=None, target_phi=0.2))
    assert res.packing.containment_report().n_outside == 0
    assert res.stats["phi"] == pytest.approx(0.2) and res.timeseries["wall_collisions"].values.max() > 0



@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_a_lone_ellipsoid_keeps_growing_under_the_two_temperature_thermostat(seed):
    """One prolate spheroid in a container, one wall collision per window, so every window ends
    with the particle at the wall. Rescaling translations and rotations by separate global
    factors turned the direction of its velocities at every window, and the map of collision and
    rescaling drove it to graze the wall: windows of 2e-9 time units or of none (seed 1: phi stuck
    at 0.032 for 20000 windows; seeds 2-4 stopped as 'jammed' at phi = 0.055, 0.10, 0.17 by the
    infinite pressure of a window of zero length). The thermostat scales the velocities of the
    particles of the last collision by one factor
    (:meth:`hardpack.md.ellipsoid_engine.EllipsoidEngine.rescale_velocities`): phi = 0.2 in 35-50
    windows (the limit 0.25 is where the long semiaxis spans the container)."""
    from hardpack.geometry.packing import Packing
    from hardpack.md import StopCriteria
    from hardpack.md.ellipsoid import compress_ellipsoids

    shape = Ellipsoids([[1.0, 0.5, 0.5]], [[1, 0, 0, 0]])
    p = Packing([[5, 5, 7.4]], lattice=10 * np.eye(3), shape=shape, boundary=SphericalContainer((5, 5, 5), 3.0))
    def at_most_100_windows(record):  # wall collisions are not counted by max_collisions
        assert len(durations) < 100, f"phi = {record['phi']} after 100 windows"
        durations.append(record["time"])

    durations = []
    res = compress_ellipsoids(p, 0.1, seed, stop=StopCriteria(max_pressure=None, target_phi=0.2),
                              progress=at_most_100_windows)
    assert res.stats["stop_reason"] == "target_phi" and res.stats["phi"] == pytest.approx(0.2)
    assert np.diff(durations).min() > 1e-3
    # the lone particle is the partner of every window's last collision, so its rotations follow
    # the translational factor (both are set at the start and after the last window, which ends
    # at the target phi, not at a collision)
    assert res.stats["rescalings_two_factors"] <= 2 and res.stats["rescalings_left_out"] == 0


# ---------------------------------------------------------------- the M&M extrapolation and its row
def _mm_packing(n, radius, phi_target):
    """n oblate spheroids 1 : 1.9 : 1.9 in a container of ``radius``; the particle size gives phi."""
    from hardpack.geometry.packing import Packing

    a = (phi_target * radius**3 / (n * 1.9**2)) ** (1 / 3)
    rng = np.random.default_rng(n)
    u = rng.standard_normal((n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    pos = radius + u * (radius - 2 * a) * rng.uniform(0, 1, (n, 1))
    shape = Ellipsoids(np.tile([a, 1.9 * a, 1.9 * a], (n, 1)), np.tile([1.0, 0, 0, 0], (n, 1)))
    return Packing(pos, lattice=2 * radius * np.eye(3), shape=shape,
                   boundary=SphericalContainer((radius,) * 3, radius), allow_overlap=True)


def _mm_summary(sizes=(250, 500, 1000, 2000), seeds=(1, 2), phi0=0.700, slope=0.5, fit_min_n=500, noise=3e-4):
    from hardpack.structure.containers import ellipsoid_container_summary

    rng = np.random.default_rng(1)
    packings, seed_list = [], []
    for n in sizes:
        for s in seeds:
            # a / R = (phi / N)^(1/3) for a = (O1 O2 O3)^(1/3): solve phi = phi0 - slope a/R by iteration
            phi = phi0
            for _ in range(50):
                phi = phi0 - slope * (phi / n) ** (1 / 3)
            packings.append(_mm_packing(n, 10.0, phi + noise * rng.standard_normal()))
            seed_list.append(s)
    return ellipsoid_container_summary(packings, seed_list, fit_min_n=fit_min_n)


def test_mm_extrapolation_recovers_a_known_line():
    ds = _mm_summary(noise=0.0)
    a = ds.attrs
    assert a["phi0"] == pytest.approx(0.700, abs=1e-12) and a["slope"] == pytest.approx(-0.5, abs=1e-10)
    assert a["n_fit"] == 6 and a["n_sizes_fit"] == 3
    # a is the geometric mean semiaxis: a/R = (phi / N)^(1/3)
    assert np.allclose(ds["a_over_R"].values, (ds["phi_avg"].values / ds["N"].values) ** (1 / 3), rtol=1e-12)


def test_mm_row_passes_fails_and_is_na_below_its_size():
    from hardpack.validation.containers import container_rows
    from hardpack.validation.rows import FAIL, NA, PASS

    def row(ds):
        return {r.target: r for r in container_rows([ds])}["donev-7.3-mm-phi0"]

    assert row(_mm_summary()).status == PASS
    assert row(_mm_summary(phi0=0.690, noise=1e-5)).status == FAIL
    assert row(_mm_summary(sizes=(30, 45, 60), seeds=(1,), fit_min_n=30)).status == NA  # smoke size
    assert row(_mm_summary(sizes=(1000, 2000), fit_min_n=500)).status == NA  # two sizes


def test_the_shape_name_picks_the_ellipsoid_row():
    """The summary's shape_name chooses the published bulk density: the same data pass as M&Ms
    (0.700) and fail as ollipsoids (0.741); a shape without a published value has no row."""
    from hardpack.validation.containers import container_rows
    from hardpack.validation.rows import FAIL, PASS

    ds = _mm_summary()
    ds.attrs["shape_name"] = "ollipsoid"
    rows = {r.target: r for r in container_rows([ds])}
    assert list(rows) == ["donev-7.3-ollipsoid-phi0"] and rows["donev-7.3-ollipsoid-phi0"].status == FAIL
    assert container_rows([_mm_summary(phi0=0.741)]) and \
        {r.status for r in container_rows([_summary_named(_mm_summary(phi0=0.741), "ollipsoid")])} == {PASS}
    assert container_rows([_summary_named(_mm_summary(), "prolate")]) == []


def _summary_named(ds, name):
    ds.attrs["shape_name"] = name
    return ds


def test_a_particle_pinned_across_the_container_stays_inside_to_round_off():
    """A prolate spheroid grown until its long axis nearly spans the container (phi -> 1/4) bounces
    between two wall contacts ~1e-10 apart in time: the wall pressure grows past 1e13 while the gap
    stays within a few times the round-off level of a located collision (64 ulps of R; measured
    -11 to -82 ulps over 3 seeds). With the pairs' shortest trace step (1e-9 of the first), longer
    than the flight between the contacts, the gap drifted to -1.7e6 ulps at Z_wall = 3e10."""
    from hardpack.geometry.packing import Packing
    from hardpack.md.ellipsoid import EllipsoidSimulation

    radius = 3.0
    s = radius * (1 - 1e-4)
    shape = Ellipsoids([[s, s / 2, s / 2]], [[1, 0, 0, 0]])
    cont = SphericalContainer((5, 5, 5), radius)
    p = Packing([[5, 5, 5]], lattice=10 * np.eye(3), shape=shape, boundary=cont)
    rng = np.random.default_rng(0)
    sim = EllipsoidSimulation(p, rng.standard_normal((1, 3)), rng.standard_normal((1, 3)), 0.1)
    sim.engine.rescale_velocities(1.0)
    worst = np.inf
    for _ in range(400):
        rec = sim.run_window(1)
        worst = min(worst, _gaps(sim.engine, cont).min())
    assert rec["Z_wall"] > 1e13
    assert worst > -256 * np.finfo(float).eps * radius, worst


def test_the_container_grid_of_ellipsoids_is_the_sphere_engines():
    """In a spherical container every axis is walled, so no periodic image caps the bounding radii
    (:meth:`hardpack.md.engine.Engine._new_bounds`): the ellipsoid engine builds its cell grid on
    the packing's own box, exactly the grid the sphere engine builds for spheres of the same
    bounding radii, and a particle as large as the container still fits under its cap."""
    from hardpack.initial import random_ellipsoid_packing

    p = random_ellipsoid_packing(200, [1.25, 1.0, 0.8], 0.1, 3, boundary="spherical_container")
    box = np.diag(p.lattice).copy()
    n = p.n_particles
    ell = EllipsoidEngine(p.positions, np.zeros((n, 3)), p.shape.semiaxes, p.shape.orientations,
                          np.zeros((n, 3)), box, boundary=p.boundary)
    sph = Engine(p.positions, np.zeros((n, 3)), p.shape.semiaxes.max(axis=1), box, boundary=p.boundary)
    skin = 0.1
    ell._new_bounds(skin)
    sph._new_bounds(skin)
    np.testing.assert_array_equal(ell.box, box)
    np.testing.assert_array_equal(ell.ncl, sph.ncl)
    np.testing.assert_array_equal(ell.rcap, sph.rcap)
    assert ell.ncl.min() >= 3  # the container is resolved by cells, not one cell for all
    # one ellipsoid nearly as large as its container: the cap (no periodic quarter-box limit) fits it
    radius = 1.0
    one = EllipsoidEngine(np.full((1, 3), radius), np.zeros((1, 3)), np.array([[0.99, 0.5, 0.4]]),
                          np.array([[1.0, 0, 0, 0]]), np.zeros((1, 3)), np.full(3, 2 * radius),
                          boundary=SphericalContainer((radius,) * 3, radius))
    one._new_bounds(skin)
    assert one.rcap[0] >= 0.99 * (1 + 1e-3)
