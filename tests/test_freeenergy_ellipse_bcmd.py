"""Linearised BCMD for ellipses (Donev 2006, secs. 6.3 and 6.4.3; Donev et al. 2007, Sec. 4.4):
the disjoint-cell rung of the ladder (independent ellipses in shrinking cells of their own shape)
and a disk packing seen as round ellipses against its exact simplex."""

import sys
from pathlib import Path

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.freeenergy import _ellipse_kernel as kern
from hardpack.freeenergy.ellipse_bcmd import ellipse_bcmd
from hardpack.freeenergy.isostatic import remove_rattlers
from hardpack.geometry.neighbours import pairs_within
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids

sys.path.insert(0, str(Path(__file__).parent))
from test_freeenergy_isostatic import LATTICE, POSITIONS, RADII  # noqa: E402


def _free_ellipses(n, seed):
    rng = np.random.default_rng(seed)
    axes = np.column_stack([rng.uniform(1.0, 3.0, n), np.ones(n)])
    phi0 = rng.uniform(0.0, np.pi, n)
    cell = np.column_stack([np.cos(phi0), np.sin(phi0), axes[:, 0], axes[:, 1]])
    im, ii = np.ones(n), 4.0 / (axes**2).sum(axis=1)
    qd = rng.normal(size=(n, 3)) * np.sqrt(np.column_stack([im, im, ii]))
    return cell, im, ii, qd


def test_disjoint_cells_kinetic_energy_scales_as_the_cell_volume():
    # n ellipses alone in cells of their own shape (Eq. C1): the cell body scales as Delta mu, so
    # its volume as Delta mu^3 and (3/2) ln(K/K0) = 3 ln(dmu0/dmu1) for a slow shrink (the
    # energy of a billiard in a homothetically shrinking domain scales as the inverse square of
    # its size, ergodic or not)
    n = 10
    cell, im, ii, qd = _free_ellipses(n, 1)
    q, tq = np.zeros((n, 3)), np.zeros(n)
    none_f, none_i = np.zeros((0, 3)), np.zeros(0, np.int64)
    start = np.zeros(n + 1, np.int64)
    counts = np.zeros(2, np.int64)

    def kinetic():
        return 0.5 * (np.sum(qd[:, :2] ** 2) + np.sum(qd[:, 2] ** 2 / ii))

    dmu0, dmu1, gamma = 1e-2, 1e-3, 3e-4
    args = (none_i, none_i, none_f, none_f, np.zeros(0), start, none_i)
    kern.run_segment(q, qd, tq, cell, im, ii, *args, 0.0, 1.0, dmu0, 0.0, 1e-16, counts, 10**8)
    k0 = kinetic()
    kern.run_segment(q, qd, tq, cell, im, ii, *args, 1.0, (dmu0 - dmu1) / gamma, dmu0, gamma,
                     1e-16, counts, 10**8)
    assert 1.5 * np.log(kinetic() / k0) == pytest.approx(3 * np.log(dmu0 / dmu1), rel=1e-3)
    # every ellipse is still inside its cell
    t = float(tq.max())
    assert max(kern.cell_value(i, t, q, qd, tq, cell, dmu1, 0.0, t) for i in range(n)) <= 0.0


def test_cell_collision_time_is_the_first_root():
    # a translating ellipse reaches the wall of its fixed cell where the cell boundary point of
    # that direction is: along the major axis (a = 2) from the centre at speed 1, at t = dmu a
    cell = np.array([[1.0, 0.0, 2.0, 1.0]])
    q, tq, qd = np.zeros((1, 3)), np.zeros(1), np.array([[1.0, 0.0, 0.0]])
    t = kern.predict_cell(0, 0.0, q, qd, tq, cell, 0.01, 0.0, 0.0, 1e-18)
    assert t == pytest.approx(0.02, rel=1e-12)
    # a shrinking wall (gamma) meets it earlier: dmu a - gamma a t = t
    t = kern.predict_cell(0, 0.0, q, qd, tq, cell, 0.01, 0.5, 0.0, 1e-18)
    assert t == pytest.approx(0.02 / 2.0, rel=1e-12)
    # a pure rotation at fixed centroid reaches the wall at dphi = dmu 2 alpha / (alpha^2 - 1)
    qd = np.array([[0.0, 0.0, 1.0]])
    t = kern.predict_cell(0, 0.0, q, qd, tq, cell, 0.01, 0.0, 0.0, 1e-18)
    assert t == pytest.approx(0.01 * 4.0 / 3.0, rel=1e-9)


@pytest.fixture(scope="module")
def round_ellipses():
    p = Packing(POSITIONS, RADII, LATTICE)
    pl = pairs_within(p, rel_gap=1e-9)
    q = remove_rattlers(p, np.bincount(np.r_[pl.i, pl.j], minlength=p.n_particles) < 3)
    return Packing(q.positions, lattice=q.lattice,
                   shape=Ellipsoids(np.stack([q.radii, q.radii], axis=1), np.zeros(q.n_particles)))


def test_round_ellipses_bcmd_matches_the_disk_simplex(round_ellipses):
    # the 62-disk backbone of test_freeenergy_isostatic as alpha = 1 ellipses (rotations fixed):
    # the exact Delta f is the disk simplex's (test_freeenergy_ellipses); BCMD from 100 times the
    # disjoint-cell point with gamma0 = 0.01, theta = 0.5 (seeds 1 and 2 gave +0.006 and -0.008)
    # must agree to the 1 % of the disk test
    n = round_ellipses.n_particles
    ds = ellipse_bcmd(round_ellipses, delta=1e-8, contact_tol=1e-9, fixed_translation=[0],
                      fixed_rotation=np.arange(n), dmu_max=1e-6, gamma0=0.01, theta=0.5, seed=1)
    a = ds.attrs
    assert (a["n_f"], a["n_eff"], a["n_contacts"]) == (122, 61, 123)
    assert abs(a["diff"]) < 0.01 * a["exact"]
    assert np.all(np.diff(ds["dmu"].values) < 0)


def test_refuses_a_packing_that_is_not_isostatic(round_ellipses):
    with pytest.raises(InvalidInputError, match="not isostatic"):
        ellipse_bcmd(round_ellipses, delta=1e-8, contact_tol=1e-9, fixed_translation=[0, 1],
                     fixed_rotation=np.arange(round_ellipses.n_particles), dmu_max=1e-6)
    with pytest.raises(InvalidInputError, match="dmu_max"):
        ellipse_bcmd(round_ellipses, delta=1e-8, contact_tol=1e-9, fixed_translation=[0],
                     fixed_rotation=np.arange(round_ellipses.n_particles), dmu_max=-1.0)
