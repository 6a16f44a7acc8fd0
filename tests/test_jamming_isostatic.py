"""The exact simplex-vertex solution of LP (4.10) for isostatic backbones agrees with HiGHS."""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.jamming import contact_network, remove_rattlers, rigidity_matrix
from hardpack.jamming.isostatic import RigidBackbone
from hardpack.jamming.lp import solve_motion


@pytest.fixture(scope="module")
def backbone(jammed_disks):
    """The jammed disks with random gaps ~1e-7 D (radii shrunk unevenly), so that the LP
    vertex is unique and the cage has a finite size."""
    rng = np.random.default_rng(0)
    disks = jammed_disks
    p = disks.replace(radii=disks.radii * (1 - rng.uniform(0, 2e-7, 64)))
    net = contact_network(p, 1e-5)
    active, _ = remove_rattlers(net, np.ones(64, bool), dr_large=1e-3, box=3.0, rng=rng)
    iso = RigidBackbone.build(net, active)
    assert iso is not None
    return net, active, iso


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_vertex_formula_matches_highs(backbone, seed):
    net, active, iso = backbone
    load = np.where(active[:, None], np.random.default_rng(seed).normal(size=(64, 2)), 0.0)
    disp, forces = iso.optimum(load, 2, box=3.0)
    lp = solve_motion(net, active, load, box=3.0, cell_length=10.0)
    # HiGHS anchors the same particle (the first active one), so the motions compare directly
    scale = np.abs(lp.displacement).max()
    assert scale > 0
    np.testing.assert_allclose(disp, lp.displacement, atol=1e-6 * scale)
    assert np.sum(load * disp) == pytest.approx(lp.objective, rel=1e-6)
    np.testing.assert_allclose(forces, lp.forces[iso.contacts], atol=1e-6 * forces.max())


def test_strain_mode_is_a_floppy_motion(backbone):
    """(dR, eps) keeps every contact closed to first order and does not change the volume."""
    net, _, iso = backbone
    dr, eps = iso.strain_mode(net, np.array([0.3, -1.0, 0.7]), box=1.0, cell_length=10.0)
    assert np.trace(eps) == pytest.approx(0.0, abs=1e-15) and np.abs(eps).max() > 0
    a = rigidity_matrix(net, strain=True)
    stretch = a.T @ np.r_[dr.ravel(), eps[0, 0], eps[1, 1], eps[0, 1]]
    assert np.abs(stretch[iso.contacts]).max() < 1e-10 * np.abs(eps).max()


def test_hyperstatic_backbone_matches_highs(jammed_disks):
    """With the next near contacts inside delta the backbone has K >= 3 self-stresses: the
    K-variable LPs (vertex of LP 4.10, jamming gap mu*) still agree with HiGHS on the full LPs."""
    import scipy.sparse as sp

    from hardpack.geometry.neighbours import pairs_within
    from hardpack.jamming.forces import backbone_rows, self_stress
    from hardpack.jamming.lp import solve_lp

    rng = np.random.default_rng(3)
    disks = jammed_disks
    p = disks.replace(radii=disks.radii * (1 - rng.uniform(0, 2e-7, 64)))
    gaps = np.sort(pairs_within(p, rel_gap=0.05).gap)
    n_tight = int((gaps < 1e-6).sum())
    for extra in range(1, 20):  # add near contacts until the backbone has 3 self-stresses
        delta = 0.5 * (gaps[n_tight + extra - 1] + gaps[n_tight + extra])
        net = contact_network(p, delta)
        active, _ = remove_rattlers(net, np.ones(64, bool), dr_large=0.1 * delta, box=3.0, rng=rng)
        iso = RigidBackbone.build(net, active)
        if iso is not None and iso.n_self_stresses >= 3:
            break
    assert iso is not None and iso.n_self_stresses >= 3
    for seed in range(3):
        load = np.where(active[:, None], np.random.default_rng(seed).normal(size=(64, 2)), 0.0)
        vertex = iso.optimum(load, 2, box=3.0)
        lp = solve_motion(net, active, load, box=3.0, cell_length=10.0)
        assert vertex is not None
        assert np.sum(load * vertex[0]) == pytest.approx(lp.objective, rel=1e-6)
        np.testing.assert_allclose(vertex[0], lp.displacement, atol=1e-6 * np.abs(lp.displacement).max())
    # jamming gap: reduced LP (through verify's self_stress) vs the full LP with HiGHS
    forces = self_stress(net, active)
    c = net.among(active)
    a = backbone_rows(net, active, c)
    full = solve_lp(net.gap[c], A_eq=sp.vstack([a, sp.csr_matrix(net.contact_distance[c][None, :])]),
                    b_eq=np.r_[np.zeros(a.shape[0]), 1.0], bounds=(0, None))
    assert forces.jamming_gap == pytest.approx(full.fun, rel=1e-6)
    assert forces.forces.min() >= 0 and np.abs(forces.imbalance).max() < 1e-12
