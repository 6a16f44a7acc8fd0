"""Algorithm 14 (sequential random loading) on packings with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.jamming import contact_network, verify
from hardpack.jamming.sequential import _wraps, collision_step, volume_step
from hardpack.jamming.workingset import WarmStart


def _shrunk(p: Packing, s: float) -> Packing:
    return p.replace(radii=p.radii * (1 - s))


def test_collision_step_head_on():
    """Two disks 0.1 apart approaching at relative speed 2 touch after t = 0.05 (less the
    round-off slack of 1e-11 of the distance)."""
    p = Packing([[0.0, 0.0], [1.1, 0.0]], [0.5, 0.5], 10 * np.eye(2))
    net = contact_network(p, delta=0.5)
    disp = np.array([[1.0, 0.0], [-1.0, 0.0]])
    assert collision_step(net, disp, None) == pytest.approx(0.05, rel=1e-9)
    assert collision_step(net, -disp, None) == np.inf  # separating pair never collides


def test_volume_step():
    """det(I + t eps) <= 1: pure shear never grows the cell; eps = diag(0.2, -0.1) crosses
    det = 1 at (1 + 0.2 t)(1 - 0.1 t) = 1, i.e. t = 5."""
    assert volume_step(np.diag([0.1, -0.1])) == np.inf
    assert volume_step(np.diag([0.2, -0.1])) == pytest.approx(5.0)
    assert volume_step(None) == np.inf


def test_sliding_rows_unjam_square_lattice():
    """Square lattice with gaps 1e-3 D in a 2 x 1 cell: rows slide (Table 4.1, C = N), so the
    first load carries the free disk as far as the neighbour list allows (delta r = 0.1 D, half
    of it relative to the median of the two disks), 50 times the gaps, far beyond the 1e-2
    threshold: not jammed, and the test stops there (Alg. 14 step 10)."""
    p = _shrunk(lattice_packing("square", (2, 1)), 1e-3)
    r = verify(p, delta=0.2, method="sequential", tests=("collective",), seed=1, threshold=1e-2,
               contact_delta=2e-3)
    assert not r.collective
    assert max(r.collective_test.mean_displacement) == pytest.approx(0.05, rel=1e-3)
    assert r.collective_test.n_lp == 1 and len(r.collective_test.mean_displacement) == 1
    r.collective_test.final.overlap_report()  # a valid packing (construction checks overlaps)


def test_triangular_with_gaps_is_jammed_within_the_gaps():
    """Triangular lattice with gaps 1e-4 D: every particle and the cell can only move within the
    gaps (strictly jammed lattice), so the sequential test reports displacements of the order
    of the gap, far below the 1e-2 threshold, in the collective and the strict test."""
    p = _shrunk(lattice_packing("triangular", (4, 4)), 1e-4)
    r = verify(p, delta=0.2, method="sequential", seed=2, threshold=1e-2, contact_delta=1e-3)
    assert r.collective and r.strict
    for out in (r.collective_test, r.strict_test):
        assert max(out.max_displacement) < 1e-2
        assert len(out.mean_displacement) == 2 * out_loads(r)


def test_all_rattlers_is_not_jammed():
    """Gaps 1e-3 D but contacts counted only within 1e-6: every disk is a rattler at that
    tolerance, nothing is left to jam (Alg. 13 step 3) -- never 'jammed' by default."""
    p = _shrunk(lattice_packing("triangular", (4, 4)), 1e-3)
    r = verify(p, delta=0.2, method="sequential", seed=1)
    assert r.rattler.all() and not r.collective and not r.strict


def out_loads(r) -> int:
    return r.params["n_loads"]


def test_killed_verification_resumes_from_its_checkpoint(tmp_path, monkeypatch, caplog):
    """A verification killed after the collective test and two strict loading sequences (an
    exception raised once the 8th checkpoint is written) resumes from the checkpoint: it solves
    only the LPs of the remaining strict sequences and ends with the outcome of an uninterrupted
    run, sequence by sequence (the random loads and the moved packing are restored); the
    checkpoint is removed at the end. The ideal method refuses a checkpoint."""
    from hardpack.errors import InvalidInputError
    from hardpack.io import checkpoint as ckpt
    from hardpack.jamming import sequential

    p = _shrunk(lattice_packing("triangular", (4, 4)), 1e-4)
    kwargs = {"delta": 0.2, "method": "sequential", "seed": 2, "threshold": 1e-2, "contact_delta": 1e-3}
    reference = verify(p, **kwargs)
    assert len(reference.collective_test.steps) == len(reference.strict_test.steps) == 6
    path = tmp_path / "verify.ckpt"
    real_save, saves = ckpt.save, []

    def killed(*args):
        real_save(*args)
        saves.append(1)
        if len(saves) == 8:
            raise KeyboardInterrupt

    monkeypatch.setattr(ckpt, "save", killed)
    with pytest.raises(KeyboardInterrupt):
        verify(p, checkpoint=path, **kwargs)
    assert path.exists()
    monkeypatch.setattr(ckpt, "save", real_save)
    real_solve, lps = sequential.solve_motion, []
    monkeypatch.setattr(sequential, "solve_motion", lambda *a, **k: lps.append(1) or real_solve(*a, **k))
    with caplog.at_level("INFO", logger="hardpack.jamming"):
        resumed = verify(p, checkpoint=path, **kwargs)
    assert "resuming the sequential tests" in caplog.text
    assert not path.exists()
    assert len(lps) == sum(reference.strict_test.steps[2:])
    for test in ("collective_test", "strict_test"):
        ref, res = getattr(reference, test), getattr(resumed, test)
        assert res.mean_displacement == ref.mean_displacement and res.steps == ref.steps
        assert res.n_lp == ref.n_lp and res.jammed == ref.jammed
        np.testing.assert_array_equal(res.displacement, ref.displacement)
        np.testing.assert_array_equal(res.final.positions, ref.final.positions)
    np.testing.assert_array_equal(resumed.strict_test.strain, reference.strict_test.strain)
    with pytest.raises(InvalidInputError, match="sequential method"):
        verify(p, delta=1e-6, checkpoint=path)


def test_every_loading_sequence_starts_from_the_given_packing():
    """The square lattice of the previous tests, with a threshold the sliding rows do not reach
    in one sequence: the load B and then -B each carry the free row over three LPs. Both start
    from the given (centrosymmetric) packing, so -B is the mirror image of B and moves it
    exactly as far (Algorithm 14 as run here, see hardpack.jamming.sequential: the text's
    sequence -B starts where B ended, and moved it 9 % less in this case)."""
    p = _shrunk(lattice_packing("square", (2, 1)), 1e-3)
    r = verify(p, delta=0.2, method="sequential", tests=("collective",), seed=1, threshold=0.25,
               contact_delta=2e-3, n_loads=1)
    forward, reverse = r.collective_test.mean_displacement
    assert r.collective_test.steps == [3, 3]
    assert forward > 0.1  # the rows slid: 3 LPs of up to delta r_min = 0.1 D
    assert reverse == pytest.approx(forward, rel=1e-9)


def test_sequences_run_side_by_side_with_the_same_outcome():
    """workers = 2 runs the loading sequences in two worker processes; recorded in order, they
    give exactly the outcome of one process (same loads, same LPs), the strict test included."""
    p = _shrunk(lattice_packing("triangular", (4, 4)), 1e-4)
    kwargs = {"delta": 0.2, "method": "sequential", "seed": 2, "threshold": 1e-2, "contact_delta": 1e-3}
    serial, parallel = verify(p, **kwargs), verify(p, workers=2, **kwargs)
    for test in ("collective_test", "strict_test"):
        one, two = getattr(serial, test), getattr(parallel, test)
        assert two.mean_displacement == one.mean_displacement and two.steps == one.steps
        np.testing.assert_array_equal(two.displacement, one.displacement)
        np.testing.assert_array_equal(two.final.positions, one.final.positions)
    np.testing.assert_array_equal(parallel.strict_test.strain, serial.strict_test.strain)


def test_a_checkpoint_of_the_older_layout_is_refused():
    """A state saved before every sequence started from the given packing (no layout version)
    would resume with other loads: refused with a message that says what to do."""
    from hardpack.errors import InvalidInputError
    from hardpack.jamming.sequential import sequential_test

    p = _shrunk(lattice_packing("triangular", (4, 4)), 1e-4)
    old = {"next_sequence": 1, "rng": "{}", "seconds": 1.0}
    with pytest.raises(InvalidInputError, match="older hardpack.*delete it"):
        sequential_test(p, 0.2, strict=False, rattlers=np.zeros(p.n_particles, bool),
                        rng=np.random.default_rng(0), box=1.0, resume=old)


def test_side_by_side_sequences_after_the_verdict_are_discarded():
    """The sliding rows of the square lattice settle 'not jammed' in the first sequence; with two
    workers the second sequence runs meanwhile, but the outcome keeps only the first, as one
    process does (Alg. 14 step 10)."""
    p = _shrunk(lattice_packing("square", (2, 1)), 1e-3)
    r = verify(p, delta=0.2, method="sequential", tests=("collective",), seed=1, threshold=1e-2,
               contact_delta=2e-3, workers=2)
    assert not r.collective
    assert r.collective_test.n_lp == 1 and len(r.collective_test.mean_displacement) == 1


def test_warm_start_survives_particles_wrapping_through_the_cell():
    """A translation by 0.37 of the cell moves a third of the particles out of it, and the
    contact network wraps them back: their contacts change image shift. The previous LP's
    columns must still be found by their keys (i, j, n + w_j - w_i), else the next LP starts
    from a basis with holes (at N = 1e4 in 3D: a second LP of 213 s instead of 28 s)."""
    p = _shrunk(lattice_packing("triangular", (4, 3)), 1e-3)
    before = contact_network(p, 0.05)
    moved = p.replace(positions=before.positions + 0.37 * p.lattice[:, 0])
    after = contact_network(moved, 0.05)
    keys = [np.column_stack([net.i, net.j, net.shift]) for net in (before, after)]
    warm = WarmStart.from_columns(np.arange(before.n_contacts), np.zeros(0, dtype=np.int64), keys[0], 2)
    changed = sum(not np.any(np.all(keys[1] == k, axis=1)) for k in keys[0])
    assert changed > 0  # some keys did change: the test exercises the wrap
    basis, _ = warm.rewrapped(_wraps(moved, after)).locate(keys[1], 2)
    assert np.sort(basis).tolist() == list(range(after.n_contacts))


@pytest.mark.parametrize("name, d", [("square", 2), ("sc", 3)])
def test_one_particle_cell_shears_at_decreasing_volume(name, d):
    """Square and SC with one particle per cell (gaps 1e-4 D): the particle is caged by its
    own images (collectively jammed), but the shear eps_12 keeps every contact at first order
    and lowers the volume at second order (Donev Table 4.1: not strictly jammed). The particle
    is its own bulk, so only the strain shows the motion: it exceeds the threshold."""
    p = _shrunk(lattice_packing(name, (1,) * d), 1e-4)
    r = verify(p, delta=0.2, method="sequential", seed=2, threshold=1e-2, contact_delta=1e-3)
    assert r.collective and not r.strict
    assert max(r.strict_test.mean_displacement) == 0.0
    assert max(r.strict_test.strain_norm) >= 1e-2
    assert r.category == "collectively jammed"


def test_a_checkpoint_of_layout_2_is_refused():
    """Layout 2 had no undetermined reason and no fallback counts: refused, not misread."""
    from hardpack.errors import InvalidInputError
    from hardpack.jamming.sequential import sequential_test

    p = _shrunk(lattice_packing("triangular", (4, 4)), 1e-4)
    old = {"version": 2, "next_sequence": 1, "rng": "{}", "seconds": 1.0}
    with pytest.raises(InvalidInputError, match="older hardpack \\(state layout 2, this one reads 3"):
        sequential_test(p, 0.2, strict=False, rattlers=np.zeros(p.n_particles, bool),
                        rng=np.random.default_rng(0), box=1.0, resume=old)
