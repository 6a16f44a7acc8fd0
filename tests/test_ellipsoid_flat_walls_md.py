"""Ellipsoids and ellipses between hard flat walls: the wall events of the ellipsoid MD
(:func:`hardpack.md._ellipsoid_kernel.wall_gap` in FLAT_WALLS_MODE; Donev 2006, sec. 3.2.2.1 and
sec. 3.5).

- A single rotating ellipsoid bouncing ~10^3 times in a slit (walls on z) and in a closed box:
  kinetic energy (translational plus rotational) is conserved to round-off, the momentum along the
  periodic axes exactly, and in the slit the angular momentum about the wall normal (the wall
  force is normal to the wall, so its torque has no normal component: a wrong lever arm breaks
  it); the exact support-point gap never goes below round-off.
- A sphere-shaped ellipsoid, and an ellipse whose semiaxis b lies along the wall normal (its
  support point then stays on the normal through the centre, so it never spins up), reproduce the
  wall collision times of the sphere kernel (a disk of radius b), without and with growth.
- The ideal-gas pressure of one particle in a slit of width L (exact, derived here): the
  configuration integral is A int dOmega (L - 2 s(Omega)) (s the support function along the wall
  normal, Omega uniform: the moment of inertia is spherically symmetric, so the kinetic energy
  does not depend on the orientation), so p A <L - 2 s> = kT, with <s> the mean half-width of the
  body (the mean radius of curvature R of Isihara and Kihara in 3D, the perimeter over 2 pi in
  2D). With no motion along the walls kT = <v_n^2>, the time average of the normal velocity
  squared, which the run measures.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate, special

from hardpack.geometry.boundaries import HardWalls
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.md.ellipsoid_engine import EllipsoidEngine, moments_of_inertia
from hardpack.md.engine import Engine


def _orient(rng, n, d):
    if d == 2:
        return rng.uniform(0, 2 * np.pi, n)
    q = rng.standard_normal((n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _containment(eng, walls):
    """Worst relative overlap with a wall (> 0 crosses it) by the packing model."""
    p = Packing(eng.positions.copy(), lattice=np.diag(eng.box), boundary=walls, allow_overlap=True,
                shape=Ellipsoids(eng.semiaxes.copy(), eng.orientations.copy()))
    return p.containment_report(1.0).overlap


@pytest.mark.parametrize("d,axes", [(3, (2,)), (3, (0, 1, 2)), (2, (1,)), (2, (0, 1))])
def test_a_single_ellipsoid_bounces_conserving_energy_and_momentum(d, axes):
    rng = np.random.default_rng(11 + d + len(axes))
    walls = HardWalls(axes)
    box = np.array([7.0, 6.0, 5.0][:d])
    semi = np.array([[1.0, 0.6, 0.3][:d]])
    nw = 3 if d == 3 else 1
    w = rng.standard_normal((1, nw)) * 3
    eng = EllipsoidEngine(box[None] / 2, rng.standard_normal((1, d)), semi, _orient(rng, 1, d),
                          w if d == 3 else w[:, 0], box, boundary=walls)
    e0 = sum(eng.energies())
    p0 = eng.momentum().copy()
    lz0 = eng.inertia[0] * eng.angular_velocities[0, 2] if d == 3 else None
    periodic = np.setdiff1d(np.arange(d), axes)
    bounces = 0
    worst = -np.inf
    momentum = np.zeros(d)
    for _ in range(40):
        res = eng.run_window(0.0, 0.5, 25, 1e9)
        bounces += res.wall_collisions
        momentum += res.wall_momentum
        worst = max(worst, _containment(eng, walls))
    assert bounces == 1000
    assert sum(eng.energies()) == pytest.approx(e0, rel=1e-10)
    assert np.array_equal(eng.momentum()[periodic], p0[periodic])
    assert (momentum[list(axes)] > 0).all() and (momentum[periodic] == 0).all()
    if axes == (2,):
        # L_z = (x v)_z + I w_z is conserved and (x v)_z alone is (v_x, v_y never change), so the
        # spin about the wall normal stays as it started
        assert eng.inertia[0] * eng.angular_velocities[0, 2] == pytest.approx(lz0, rel=1e-10, abs=1e-12)
    assert worst < 1e-12
    # the rotation exchanged energy with the translation (the lever arm is not along the normal)
    assert eng.energies()[1] != pytest.approx(0.5 * (w**2).sum() * moments_of_inertia(semi)[0], rel=1e-3)


@pytest.mark.parametrize("kappa", [0.0, 0.02])
def test_a_sphere_shaped_ellipsoid_hits_the_walls_when_the_sphere_kernel_says(kappa):
    rng = np.random.default_rng(9)
    d = 3
    box = np.array([6.0, 5.0, 4.0])
    walls = HardWalls((0, 1, 2))
    x0 = box / 2 + rng.uniform(-1, 1, d)
    v0 = rng.standard_normal(d)
    r = 0.5
    ell = EllipsoidEngine(x0[None], v0[None], np.full((1, d), r), _orient(rng, 1, d),
                          rng.standard_normal((1, 3)), box, boundary=walls)
    sph = Engine(x0[None].copy(), v0[None].copy(), np.array([r]), box, boundary=walls)
    for _ in range(30):
        a = ell.run_window(kappa, 0.3, 1, 1e9)
        b = sph.run_window(kappa, 0.3, 1, 1e9)
        assert a.wall_collisions == b.wall_collisions == 1
        assert a.duration == pytest.approx(b.duration, rel=1e-11, abs=1e-13)
        assert np.allclose(ell.positions, sph.positions, rtol=0, atol=1e-10)
        assert np.allclose(ell.velocities, sph.velocities, rtol=0, atol=1e-10)
        assert np.allclose(a.wall_momentum, b.wall_momentum, rtol=1e-10)


@pytest.mark.parametrize("kappa", [0.0, 0.01])
def test_an_ellipse_with_a_semiaxis_along_the_normal_bounces_as_a_disk(kappa):
    """Semiaxes (a, b) with a along x, walls on y: the support point along +-e_y is (0, +-b), on the
    normal through the centre, so the wall exerts no torque and the ellipse (not spinning) moves
    as a disk of radius b; along x (periodic) it never meets anything."""
    box = np.array([40.0, 5.0])  # long enough that the growing bounding circle never resets the grid
    walls = HardWalls((1,))
    x0, v0 = np.array([[4.0, 2.2]]), np.array([[0.7, -1.3]])
    ell = EllipsoidEngine(x0.copy(), v0.copy(), np.array([[2.0, 0.8]]), np.array([0.0]), np.array([0.0]), box,
                          boundary=walls)
    disk = Engine(x0.copy(), v0.copy(), np.array([0.8]), box, boundary=walls)
    for _ in range(20):
        a = ell.run_window(kappa, 0.3, 1, 1e9)
        b = disk.run_window(kappa, 0.3, 1, 1e9)
        assert a.wall_collisions == b.wall_collisions == 1
        assert a.duration == pytest.approx(b.duration, rel=1e-11, abs=1e-13)
        assert np.allclose(ell.positions, disk.positions, rtol=0, atol=1e-10)
        assert np.allclose(ell.velocities, disk.velocities, rtol=0, atol=1e-10)
        assert ell.angular_velocities[0] == 0.0
    # the first bounce, by hand: at y = b (kappa = 0) after (2.2 - 0.8) / 1.3
    if kappa == 0.0:
        fresh = EllipsoidEngine(x0.copy(), v0.copy(), np.array([[2.0, 0.8]]), np.array([0.0]), np.array([0.0]),
                                box, boundary=walls)
        assert fresh.run_window(0.0, 0.3, 1, 1e9).duration == pytest.approx(1.4 / 1.3, rel=1e-13)


def _mean_half_width(semi):
    """<s>: the support function sqrt(sum_k a_k^2 u_k^2) along a direction u uniform on the
    circle or sphere (2D: perimeter / (2 pi) = (2 a / pi) E(1 - b^2 / a^2); 3D by quadrature over
    the sphere)."""
    if len(semi) == 2:
        a, b = max(semi), min(semi)
        return 4 * a * special.ellipe(1 - (b / a) ** 2) / (2 * np.pi)
    a, b, c = semi

    def support(phi, t):
        u = (np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t))
        return np.sqrt((a * u[0]) ** 2 + (b * u[1]) ** 2 + (c * u[2]) ** 2) * np.sin(t)

    return integrate.dblquad(support, 0, np.pi, 0, 2 * np.pi, epsabs=1e-12, epsrel=1e-12)[0] / (4 * np.pi)


@pytest.mark.parametrize("d,semi", [(2, (1.0, 0.4)), (3, (1.0, 0.6, 0.3))])
def test_one_particle_presses_a_slit_with_the_ideal_gas_law_of_its_mean_width(d, semi):
    """A triaxial ellipsoid: a spheroid alone in a slit keeps its spin about the symmetry axis (the
    wall torque r_C x n is normal to the plane of the axis and n) besides the spin about the wall
    normal, and the two together bias its orientations (measured: 0.863 instead of 1 for a
    spheroid (1, 0.4, 0.4)); a triaxial ellipsoid conserves only the latter, which leaves the
    orientations uniform."""
    rng = np.random.default_rng(3 + d)
    width = 3.0
    box = np.full(d, 8.0)
    box[-1] = width
    walls = HardWalls((d - 1,))
    v = np.zeros((1, d))
    v[0, -1] = 1.0  # no motion along the walls (it would be conserved; the normal one is measured)
    inertia = moments_of_inertia(np.array([semi]))
    w = rng.standard_normal((1, 3 if d == 3 else 1)) / np.sqrt(inertia)[:, None]
    eng = EllipsoidEngine(box[None] / 2, v, np.array([semi]), _orient(rng, 1, d), w if d == 3 else w[:, 0],
                          box, boundary=walls)
    mean_s = _mean_half_width(semi)
    ratios = []
    for _ in range(200):
        res = eng.run_window(0.0, 0.3, 2000, 1e9)
        # p A <L - 2s> / <v_n^2>: p = J / (2 A T) over both walls, <v_n^2> = 2 KE dt / T
        ratios.append(res.wall_momentum[-1] * (width - 2 * mean_s) / (4 * res.ke_integral))
    ratios = np.array(ratios)
    mean, se = ratios.mean(), ratios.std(ddof=1) / np.sqrt(len(ratios))
    assert abs(mean - 1) < 4 * se, (mean, se)
    assert se < 0.004
    # the extreme widths are far off: the mean half-width, not the smallest or largest semiaxis
    for s in (min(semi), max(semi)):
        assert abs(mean * (width - 2 * s) / (width - 2 * mean_s) - 1) > 10 * se


# ---------------------------------------------------------------- start, compression, storage, CLI
def test_the_start_between_walls_is_seeded_inside_and_refuses_impossible_requests():
    from hardpack.errors import InvalidInputError
    from hardpack.initial import random_ellipsoid_packing

    p = random_ellipsoid_packing(40, [1.0, 0.5, 0.5], 0.05, 3, boundary="hard_walls", wall_axes=[2])
    q = random_ellipsoid_packing(40, [1.0, 0.5, 0.5], 0.05, 3, boundary="hard_walls", wall_axes=[2])
    assert np.array_equal(p.positions, q.positions) and p.boundary.axes == (2,)
    assert p.containment_report(0.0).n_outside == 0 and p.overlap_report().n_overlapping == 0
    assert p.phi == pytest.approx(0.05)
    with pytest.raises(InvalidInputError, match="wall_axes is for"):
        random_ellipsoid_packing(4, [1.0, 0.5], 0.05, 3, wall_axes=[0])
    with pytest.raises(InvalidInputError, match="shorter than the largest particle"):
        random_ellipsoid_packing(1, [1.0, 0.1], 0.9, 3, boundary="hard_walls")


@pytest.mark.parametrize("d,wall_axes", [(3, [2]), (2, None)])
def test_compression_between_walls_jams_inside_and_round_trips(tmp_path, d, wall_axes):
    from hardpack.initial import random_ellipsoid_packing
    from hardpack.io import load_packing
    from hardpack.md import StopCriteria
    from hardpack.md.ellipsoid import compress_ellipsoids

    axes = [1.0, 1.0, 1 / 1.9] if d == 3 else [1.0, 0.5]
    p = random_ellipsoid_packing(30, axes, 0.1, 5, boundary="hard_walls", wall_axes=wall_axes)
    res = compress_ellipsoids(p, 0.1, 1, stop=StopCriteria(max_pressure=1e6), final_growth_rate=0.01,
                              switch_pressure=100)
    final = res.packing
    assert str(final.boundary) == str(p.boundary)
    assert res.stats["containment_check"] == "passed" and res.stats["max_wall_overlap"] <= 1e-9
    assert res.stats["Z"] >= 1e6 and res.stats["phi"] > (0.5 if d == 3 else 0.7)
    assert np.nanmax(res.timeseries["wall_collisions"].values) > 0
    # the wall pressure is finite and of the order of the bulk one at jamming
    assert 0.1 < res.stats["Z_wall"] / res.stats["Z"] < 10
    # the jammed packing touches the walls: the smallest support-point gap is far below the size
    assert -1e-9 < -final.containment_report(1.0).overlap < 1e-4
    res.save(tmp_path / "j.nc")
    back = load_packing(tmp_path / "j.nc")
    assert np.array_equal(back.positions, final.positions) and str(back.boundary) == str(final.boundary)


def test_cli_init_and_compress_ellipses_between_walls(tmp_path):
    from hardpack.cli import main
    from hardpack.io import load_packing

    start, out = tmp_path / "s.nc", tmp_path / "j.nc"
    assert main(["init", "--n", "24", "--d", "2", "--phi", "0.1", "--seed", "2", "--semiaxes", "1", "0.5",
                 "--boundary", "hard_walls", "--wall-axes", "1", "--out", str(start)]) == 0
    p = load_packing(start)
    assert p.shape.kind == "ellipsoid" and p.boundary.kind == "hard_walls" and p.boundary.axes == (1,)
    assert main(["compress", "--init", str(start), "--out", str(out), "--growth-rate", "0.1",
                 "--max-pressure", "1e5", "--seed", "1"]) == 0
    jammed = load_packing(out)
    assert str(jammed.boundary) == str(p.boundary) and jammed.containment_report().n_outside == 0


@pytest.mark.slow
@pytest.mark.parametrize("d,axes,wall_axes,seed", [(2, [1.5, 1.0], None, 1), (2, [1.5, 1.0], None, 2),
                                                    (3, [1.25, 1.0, 0.8], [2], 1)])
def test_ls_packings_between_walls_are_hypostatic_and_jammed_at_second_order(d, axes, wall_axes, seed):
    """Donev 2006, sec. 5.6: LS packings of ellipses and ellipsoids are jammed although hypostatic
    (fewer contacts than degrees of freedom), which the second-order test shows. Here between hard
    walls (a closed box of 20 ellipses, a slit of 20 ellipsoids), compressed to p = 1e12 with a
    slow final stage; the wall contacts are constraints of the tests."""
    from hardpack.initial import random_ellipsoid_packing
    from hardpack.jamming.result import Verdict
    from hardpack.jamming.second_order import verify_ellipsoids
    from hardpack.md import StopCriteria
    from hardpack.md.ellipsoid import compress_ellipsoids

    p = random_ellipsoid_packing(20, axes, 0.1 if d == 2 else 0.05, seed, boundary="hard_walls",
                                 wall_axes=wall_axes)
    res = compress_ellipsoids(p, 0.1, seed, stop=StopCriteria(max_pressure=1e12), final_growth_rate=3e-3,
                              switch_pressure=1e3)
    r = verify_ellipsoids(res.packing)
    assert r.verdict == Verdict.JAMMED and r.order == "second", r.summary()
    assert r.isostaticity_gap < 0 and r.n_backbone_wall_contacts > 0
