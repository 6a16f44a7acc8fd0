"""Hypostatic packings: the sequential test must unjam them, and their forces are those of the
nearest jamming point; the working-set LP solver against HiGHS.

References: a contact network with fewer than d(N-1) + 1 contacts cannot be jammed (Donev
2006, Eq. 4.8); the honeycomb lattice (Z = 3 < 4) is not collectively jammed (Table 4.1). An
isostatic network has a unique self-stress (Donev 2006, sec. 5.4.1.2), so when one of its contacts is
opened by 1e-7 D the self-stress of the nearest jamming point must be exactly that one.
"""

from __future__ import annotations

import logging

import numpy as np
import pytest
import scipy.sparse as sp

from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.jamming import contact_network, remove_rattlers, rigidity_matrix, verify, workingset
from hardpack.jamming.ideal import cell_length
from hardpack.jamming.lp import random_load, random_strain_load, solve_motion


def _opened(p: Packing, gap: float) -> tuple[Packing, int]:
    """``p`` (exact isostatic contacts) with one backbone contact opened by ``gap`` and every
    other contact kept exact to first order: the least-norm change of positions and radii with
    A^T dx - (dr_i + dr_j) = gap e_k. The contact is one whose loss leaves every backbone disk
    locally jammed. Returns the packing and the number of backbone disks."""
    net = contact_network(p, 1e-9)
    rng = np.random.default_rng(0)
    backbone, _ = remove_rattlers(net, np.ones(p.n_particles, bool), dr_large=1e-9, box=1.0, rng=rng)
    c = np.flatnonzero(net.among(backbone))
    for k in c:
        left, _ = remove_rattlers(net.subset(c[c != k]), backbone, dr_large=1e-9, box=1.0, rng=rng)
        if left.sum() == backbone.sum():
            break
    n, d = p.n_particles, p.dim
    radius_rows = np.zeros((c.size, n))
    radius_rows[np.arange(c.size), net.i[c]] += 1.0
    radius_rows[np.arange(c.size), net.j[c]] += 1.0
    system = np.hstack([rigidity_matrix(net).toarray()[:, c].T, -radius_rows])
    change = np.linalg.lstsq(system, np.where(c == k, gap, 0.0), rcond=None)[0]
    radii = p.radii + change[n * d:]
    radii[~backbone] *= 1 - 1e-4  # rattlers: room for their moved neighbours
    return Packing(net.positions + change[: n * d].reshape(n, d), radii, p.lattice), int(backbone.sum())


def test_forces_of_the_nearest_jamming_point_restore_the_open_contact(jammed_disks):
    """One contact of an isostatic disk packing opened by ~3e-7: at the contact tolerance 1e-8
    the backbone is one contact short (no self-stress); the forces of the nearest jamming point
    close exactly that contact and equal the unique self-stress of the full network to round-off."""
    q, n_backbone = _opened(jammed_disks, 1e-6)
    full = verify(q, delta=1e-5, tests=("local",))
    short = verify(q, delta=1e-8, tests=("local",))
    assert full.statics.isostaticity_gap == 0 and short.statics.isostaticity_gap == -1
    assert short.statics.n_backbone == n_backbone and short.params["force_near_contacts"] == 1
    reference = {(i, j, tuple(s)): f for i, j, s, f in
                 zip(full.network.i, full.network.j, full.network.shift, full.forces.forces)}
    mine = short.network
    expected = [reference[(i, j, tuple(s))] for i, j, s in zip(mine.i, mine.j, mine.shift)]
    np.testing.assert_allclose(short.forces.forces, expected, atol=1e-12)
    assert np.abs(short.forces.imbalance).max() < 1e-12


def test_hypostatic_honeycomb_unjams_under_sequential_loading():
    """Honeycomb (Z = 3: M = 1.5 N < 2 N - 1, hypostatic by construction) with gaps 1e-4 D: the
    first load already moves the disks by ~0.03 D, 300 times the gaps and 30 times the
    threshold: not collectively jammed."""
    p = lattice_packing("honeycomb", (2, 2))
    p = p.replace(radii=p.radii * (1 - 1e-4))
    r = verify(p, method="sequential", seed=1, contact_delta=1e-3)
    assert r.statics.isostaticity_gap < 0
    assert not r.collective and max(r.collective_test.mean_displacement) > 0.01


def test_jammed_disks_stay_within_their_gaps(jammed_disks):
    """The exactly jammed isostatic disks: no load moves the backbone by more than round-off in
    the collective test (threshold 1e-3), while the fixed cell lets the strict test shear them
    (Donev 2006, sec. 4.7.2.1: fixed-cell packings are not strictly jammed)."""
    r = verify(jammed_disks, method="sequential", seed=1)
    assert r.collective and max(r.collective_test.mean_displacement) < 1e-8
    assert not r.strict and r.strict_test.n_lp <= 3


def test_tiled_isostatic_packing_is_hypostatic_and_not_collectively_jammed(jammed_disks):
    """Four periodic copies of the isostatic disks keep every contact (4 M_b = 4 (2 N_b - 1))
    but gain degrees of freedom (2 (4 N_b - 1)): three contacts short of d(N-1) + 1 (Eq. 4.8),
    so the copies can move against each other and the ideal test (Algorithm 13) must unjam the
    tiled packing, while the original is collectively jammed. The counting is exact; it is why
    benchmarks of jamming tests may tile a packing for scaling but not for a jammed verdict."""
    p = jammed_disks
    one = verify(p, tests=("local", "collective"), seed=2)
    tiled = verify(p.tiled(2), tests=("local", "collective"), seed=2)
    assert one.collective and one.statics.isostaticity_gap == 0
    assert tiled.statics.n_backbone == 4 * one.statics.n_backbone
    assert tiled.statics.isostaticity_gap == -3
    assert not tiled.collective
    assert tiled.collective_test.max_displacement > 1e3 * tiled.params["dr_large"]


@pytest.mark.parametrize("strict", [False, True])
def test_working_set_matches_highs(strict, jammed_disks):
    """The sparse-LU working-set solver (cold -- for the strict LP through the strain
    continuation -- and warm-started for the reversed load) returns the optimum HiGHS finds for
    LP 4.10 on the first coordination shell of slightly opened jammed disks (two independent
    solvers; the tolerance is HiGHS's 1e-10)."""
    q, _ = _opened(jammed_disks, 1e-3)
    net = contact_network(q, 0.1)
    rng = np.random.default_rng(5)
    moving = np.ones(q.n_particles, bool)
    load = random_load(rng, moving, 2)
    length = cell_length(q.lattice)
    eps = random_strain_load(rng, 2, length) * 1e-3 if strict else None
    common = {"box": 0.05, "cell_length": length}
    warm = None
    for sign in (1.0, -1.0):
        strain = None if eps is None else sign * eps
        exact = solve_motion(net, moving, sign * load, strain_load=strain, working_set=False, **common)
        mine = solve_motion(net, moving, sign * load, strain_load=strain, warm=warm, **common)
        assert mine.solver == "working-set"
        warm = mine.warm
        assert mine.objective == pytest.approx(exact.objective, rel=1e-7)
        np.testing.assert_allclose(mine.displacement, exact.displacement, atol=1e-8)


def test_strain_continuation_stops_at_an_interior_strain(monkeypatch, jammed_disks):
    """The strain continuation ends at the first stage whose optimal strain is inside its
    bound (lp._strain_continuation): that optimum must be the optimum HiGHS finds with the full
    bound. With a box of 5 D the contacts bound the strain at ~0.035 of the box (measured), so
    the stage with a tenth of the bound is interior and the last stage is skipped (counted, so
    the test exercises the shortcut); tolerance as in test_working_set_matches_highs."""
    import hardpack.jamming.lp as lp

    q, _ = _opened(jammed_disks, 1e-3)
    net = contact_network(q, 0.1)
    moving = np.ones(q.n_particles, bool)
    length = cell_length(q.lattice)
    common = {"box": 5.0, "cell_length": length}
    calls = []
    solve = lp.solve_working_set
    monkeypatch.setattr(lp, "solve_working_set", lambda *a, **k: calls.append(1) or solve(*a, **k))
    early = 0
    for seed in range(4):
        rng = np.random.default_rng(seed)
        load = random_load(rng, moving, 2)
        eps = random_strain_load(rng, 2, length)
        calls.clear()
        mine = solve_motion(net, moving, load, strain_load=eps, **common)
        early += len(calls) < 6  # the continuation has 6 stages by default
        exact = solve_motion(net, moving, load, strain_load=eps, working_set=False, **common)
        assert mine.solver == "working-set"
        assert mine.objective == pytest.approx(exact.objective, rel=1e-7)
        np.testing.assert_allclose(mine.displacement, exact.displacement, atol=1e-8)
    assert early == 4


@pytest.mark.parametrize("strict", [False, True])
def test_working_set_returns_a_regular_basis_of_active_columns(monkeypatch, strict, jammed_disks):
    """The basis a working-set LP hands to the next one (workingset._KLP.optimal_basis, read
    off the simplex pivots of the K-LP) is a vertex basis of the optimum: its columns are
    linearly independent (numerical rank = their number) and all of them are active at the
    optimal motion (slack 0 to the LP tolerance, 1e-10 of the box). A choice by load alone
    takes zero-load columns at a degenerate optimum, which need not be either."""
    import hardpack.jamming.lp as lp

    q, _ = _opened(jammed_disks, 1e-3)
    net = contact_network(q, 0.1)
    moving = np.ones(q.n_particles, bool)
    length = cell_length(q.lattice)
    seen = []
    solve = lp.solve_working_set

    def spy(g, h, c, upper, **kw):
        sol = solve(g, h, c, upper, **kw)
        seen.append((workingset._Columns(sp.csc_matrix(g), np.asarray(h, float), np.asarray(upper, float)), sol))
        return sol

    monkeypatch.setattr(lp, "solve_working_set", spy)
    warm = None
    for seed in range(3):
        rng = np.random.default_rng(seed)
        load = random_load(rng, moving, 2)
        eps = random_strain_load(rng, 2, length) * 1e-3 if strict else None
        warm = solve_motion(net, moving, load, strain_load=eps, box=0.05, cell_length=length, warm=warm).warm
    assert len(seen) >= 3
    for cols, sol in seen:
        basis = cols.matrix(sol.basis).toarray()
        assert np.linalg.matrix_rank(basis) == sol.basis.size
        assert np.abs(cols.slacks(sol.x)[sol.basis]).max() <= 1e-10 * 0.05


def test_long_working_set_lps_log_their_rounds(monkeypatch, caplog, jammed_disks):
    """A working-set LP logs each round once it has run PROGRESS_AFTER seconds (progress of
    the > 1 h LPs at N = 1e4); set to -1 s here so that every round is long, and to 1 h so
    that none is."""
    q, _ = _opened(jammed_disks, 1e-3)
    net = contact_network(q, 0.1)
    moving = np.ones(q.n_particles, bool)
    load = random_load(np.random.default_rng(5), moving, 2)
    common = {"box": 0.05, "cell_length": cell_length(q.lattice)}
    for after, logged in ((3600.0, False), (-1.0, True)):
        monkeypatch.setattr(workingset, "PROGRESS_AFTER", after)
        caplog.clear()
        with caplog.at_level(logging.INFO, logger="hardpack.jamming.workingset"):
            mine = solve_motion(net, moving, load, **common)
        assert mine.solver == "working-set"
        rounds = [r.getMessage() for r in caplog.records if "working set, round" in r.getMessage()]
        assert bool(rounds) == logged
        if logged:
            assert rounds[0].startswith("working set, round 1:") and "columns violated" in rounds[0]
