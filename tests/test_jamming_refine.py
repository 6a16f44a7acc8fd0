"""Refinement of LS ellipsoid packings to the jamming point of their contacts
(hardpack.jamming.refine): Newton's method on the KKT equations of growing the particles.

Stored packings (tests/data): M&M-shaped oblate spheroids (alpha = 1.9, N = 80, LS at the final
rate 1e-3 to p = 1e12, seeds 1 and 2), near-sphere ellipsoids (1 : 1.05^(1/2) : 1.05 and
1 : 1.02^(1/2) : 1.02 and 1 : 1 : 1.02 at the final rate 1e-4, N = 100) and 30 ellipses of
semiaxes 1 and 0.8 in a closed box (``random_ellipsoid_packing(30, [1, 0.8], 0.3, 1,
boundary="hard_walls", wall_axes=[0, 1])``, then ``compress_ellipsoids`` at 1e-2 to p = 1e3 and at
1e-4 to p = 1e10, seed 1), and, in spherical containers, 20 ellipses of semiaxes 1 and 0.5 and 24 M&M-shaped
spheroids of semiaxes 1 : 1.9 : 1.9 (the same with ``boundary="spherical_container"`` at phi = 0.1
and without the box options).
The refined configuration's gaps are checked by the pair search of Packing.overlap_report and
ellipsoid_contacts, its balance by the verifier's own A F, and Newton's quadratic convergence
checks the contact Hessians against the Perram-Wertheim function.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from hardpack.errors import InvalidInputError
from hardpack.io import dataset_to_packing, load_dataset
from hardpack.jamming import refine as refine_module
from hardpack.jamming.ellipsoids import contacts_of_pairs, ellipsoid_contacts
from hardpack.jamming.highs import LPFailure
from hardpack.jamming.refine import (
    MAX_STEP,
    _next_network,
    _solve,
    refine_jamming_point,
    verify_at_jamming_point,
)
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import verify_ellipsoids

DATA = Path(__file__).parent / "data"


def _packing(name):
    return dataset_to_packing(load_dataset(DATA / f"{name}.nc"), allow_overlap=True)


def test_newton_reaches_the_jamming_point_quadratically():
    """M&M seed 2: the near self-stress balances to 4e-7; three Newton steps reach gaps and balance
    of 1e-13. Quadratic convergence checks the Jacobian (the contact Hessians in K and the gap rows)
    against the Perram-Wertheim function that the iterates are evaluated with; the gaps of the
    refined packing, read by the independent pair search of Packing.overlap_report, are zero to
    1e-12 and no other pair overlaps."""
    packing = _packing("mm_n80_seed2_slow_p1e12")
    res = verify_ellipsoids(packing, delta="gaps")
    ref = refine_jamming_point(packing, res)
    assert ref.converged and ref.iterations <= 5 and ref.overlaps == 0
    assert ref.balance[0] > 1e-8 and ref.balance[-1] < 1e-12 and ref.gap[-1] < 1e-12
    # quadratic: each step at most 100 times the square of the previous one (measured: about 12 times;
    # steps 2.8e-4, 9.2e-7, 1.1e-11 in particle sizes); a linear rate of 0.1 would fail
    assert ref.steps[-1] < 1e-9 and all(b <= 100 * a**2 + 1e-13 for a, b in zip(ref.steps, ref.steps[1:]))
    # the first Newton step is the distance the verifier estimated from the floppy modes
    assert ref.steps[0] == pytest.approx(res.collective.jamming_distance, rel=0.05)
    report = ref.packing.overlap_report(1e-12)
    assert report.n_overlapping == 0 and report.overlap > -1e-12  # touching pairs, none overlapping
    net = ellipsoid_contacts(ref.packing, 1e-9)
    assert net.n_contacts == res.collective.n_constraints and np.abs(net.gap).max() < 1e-12
    assert abs(ref.size_change) < 1e-8 and ref.forces.min() > 0


def test_verdict_at_the_jamming_point():
    """The verifier on the refined configuration: the same floppy space, an exact self-stress, and
    lambda_min(K_V) within 1 % of the packing's (jammed at second order either way)."""
    packing = _packing("mm_n80_seed2_slow_p1e12")
    before = verify_ellipsoids(packing, delta="gaps")
    after = verify_at_jamming_point(packing, delta="gaps")
    assert after.params["refined"] == 1 and "jamming point" in after.collective.reason
    assert (after.verdict, after.order) == (before.verdict, before.order) == (Verdict.JAMMED, "second")
    assert after.collective.n_floppy == before.collective.n_floppy == 3
    assert after.collective.lambda_min == pytest.approx(before.collective.lambda_min, rel=1e-2)
    assert after.collective.stress_residual < 1e-12 < before.collective.stress_residual
    ds = after.to_dataset()
    assert ds.attrs["refined"] == 1 and ds.attrs["refine_iterations"] <= 5


def test_marginal_packing_is_not_refined_and_says_why():
    """M&M seed 1: one floppy mode with lambda_min(K_V) = -1.7e-4 max |K|, 1.9e-3 particle sizes from
    the jamming point of its contacts: Newton does not converge (the jamming point is ill-defined at
    second order), so the verdict is the packing's own, with the reason."""
    packing = _packing("mm_n80_seed1_slow_p1e12")
    res = verify_at_jamming_point(packing, delta="gaps")
    assert res.params["refined"] == 0 and "did not converge" in res.params["refine_note"]
    assert "did not converge" in res.collective.reason
    assert res.collective.n_floppy == 1 and res.collective.jamming_distance > 1e-3


@pytest.mark.slow
def test_near_sphere_packing_is_jammed_at_its_jamming_point():
    """Near the sphere point the torque rows are O(alpha - 1): Newton turns particles by 0.045 rad
    and converges, but at the jamming point of the LS contacts three other pairs overlap (missed
    contacts, Donev 2006, Sec. 5.6). They join the network (active set) and the next Newton run
    converges with no overlap (measured: 2 overlapping and 1 touching pair join): there the packing
    is exactly balanced, still hypostatic (Z < 12),
    and jammed at second order (Donev 2006, Sec. 5.6: 'second-order jammed, even very close to
    the sphere point')."""
    packing = _packing("self_dual_a1.05_n100_slow_p1e12")
    res = verify_ellipsoids(packing, delta="gaps")
    one = refine_jamming_point(packing, res, rounds=1)
    assert one.converged and one.overlaps > 0 and one.steps[0] > 0.01 and one.added == 0
    ref = refine_jamming_point(packing, res)
    assert ref.converged and ref.overlaps == 0 and ref.added >= one.overlaps  # overlapping and touching pairs
    assert ref.balance[-1] < 1e-12 and ref.gap[-1] < 1e-12 and ref.forces.min() > 0
    out = verify_at_jamming_point(packing, delta="gaps")
    assert out.params["refined"] == 1 and out.params["refine_added"] == ref.added
    assert out.params["ascended"] == 0 and out.params["ascent_confirmed"] == -1  # jammed: no ascent
    assert (out.verdict, out.order) == (Verdict.JAMMED, "second")
    assert out.isostaticity_gap < 0 and out.z_mean < 12 and not out.rattler.any()
    assert out.collective.n_constraints == res.collective.n_constraints + ref.added


def test_an_unjammed_jamming_point_is_confirmed_by_the_size_ascent():
    """Self-dual alpha = 1.02 (N = 100, LS at the final rate 1e-4 to p = 1e12, seed 1 of the full
    config): the jamming point of its contacts is second-order flexible (lambda_min of K_V
    -4e-4 of the stiffness scale). The size ascent along that mode finds a packing without
    overlaps that is denser than the jamming point (measured 1.3e-6), which is an explicit
    unjamming. Without ``confirm`` no ascent runs. (Fig. 5.5 and its flexible variant check the
    ascent itself: tests/test_jamming_ascent.py.)"""
    packing = _packing("self_dual_a1.02_n100_seed1_rate1e-4_p1e12")
    out = verify_at_jamming_point(packing, delta="gaps")
    assert out.params["refined"] == 1 and (out.verdict, out.order) == (Verdict.NOT_JAMMED, "second")
    assert out.collective.lambda_min < 0 and out.isostaticity_gap < 0
    assert out.params["ascent_confirmed"] == 1 and out.params["ascent_gain"] > 1e-7
    assert "confirmed: moved by" in out.collective.reason
    quick = verify_at_jamming_point(packing, delta="gaps", confirm=False)
    assert quick.verdict == Verdict.NOT_JAMMED and quick.params["ascent_confirmed"] == -1
    assert quick.params["ascended"] == 0 and "ascent_gain" not in quick.params


def test_newton_reaches_the_jamming_point_after_the_size_ascent(monkeypatch):
    """Prolate alpha = 1.02 (N = 100, LS at the final rate 1e-4 to p = 1e12, seed 2 of the full
    config): Newton diverges from the packing as given (a step of 12 semiaxes: the floppy modes
    leave the packing far from its jamming point). After the SLP size ascent it converges, and
    the jamming point is hypostatic and jammed at second order. Without the retry the verdict
    is undetermined."""
    packing = _packing("prolate_a1.02_n100_seed2_rate1e-4_p1e12")
    plain = verify_at_jamming_point(packing, delta="gaps", retry_after_ascent=False)
    assert plain.params["refined"] == 0 and "diverged" in plain.params["refine_note"]
    assert plain.verdict == Verdict.UNDETERMINED
    out = verify_at_jamming_point(packing, delta="gaps")
    assert out.params["refined"] == 1 and out.params["ascended"] == 1
    assert 0 < out.params["ascent_phi_change"] < 1e-6
    assert out.params["refine_note"].startswith("Newton from the packing as given failed")
    assert (out.verdict, out.order) == (Verdict.JAMMED, "second") and out.isostaticity_gap < 0
    assert "LPs by highs-ds" in out.params["refine_note"]  # N = 100: the dual simplex (ascent.IPM_ABOVE)
    # above ascent_max_particles the retry is skipped, and the note says so
    large = verify_at_jamming_point(packing, delta="gaps", ascent_max_particles=50)
    assert large.verdict == Verdict.UNDETERMINED and large.params["ascended"] == 0
    assert "no retry after the size ascent above N = 50" in large.params["refine_note"]
    for bad in (-1, 1.5, True, "400"):
        with pytest.raises(InvalidInputError, match="ascent_max_particles"):
            verify_at_jamming_point(packing, delta="gaps", ascent_max_particles=bad)

    # a solver failure inside the ascent leaves the first verdict, with a note, not a crash
    def failing(*args, **kwargs):
        raise LPFailure("HiGHS returned status 4: numerical trouble")

    monkeypatch.setattr(refine_module, "ascend", failing)
    failed = verify_at_jamming_point(packing, delta="gaps")
    assert failed.verdict == Verdict.UNDETERMINED and "the size ascent failed" in failed.params["refine_note"]


def test_bad_input_is_refused():
    packing = _packing("mm_n80_seed2_slow_p1e12")
    res = verify_ellipsoids(packing, delta="gaps")
    with pytest.raises(InvalidInputError, match="max_iter"):
        refine_jamming_point(packing, res, max_iter=0)
    with pytest.raises(InvalidInputError, match="rounds"):
        refine_jamming_point(packing, res, rounds=1.5)
    with pytest.raises(InvalidInputError, match="tol"):
        refine_jamming_point(packing, res, tol=float("nan"))
    with pytest.raises(InvalidInputError, match="particles"):
        refine_jamming_point(_packing("self_dual_a1.05_n100_slow_p1e12"), res)


def test_cli_refine(tmp_path, capsys):
    """``hardpack verify --delta gaps --refine`` stores the verdict at the jamming point with the
    refinement's attributes; sphere packings refuse --refine."""
    from hardpack.cli import main
    from hardpack.geometry.lattices import lattice_packing
    from hardpack.io import save_packing

    out = tmp_path / "verdict.nc"
    assert main(["verify", str(DATA / "mm_n80_seed2_slow_p1e12.nc"), "--out", str(out), "--delta", "gaps",
                 "--refine"]) == 0
    ds = load_dataset(out)
    assert ds.attrs["refined"] == 1 and ds.attrs["jammed"] == 1 and ds.attrs["order"] == "second"
    assert "Newton converged" in ds.attrs["refine_note"]
    spheres = tmp_path / "fcc.nc"
    save_packing(lattice_packing("fcc", (2, 2, 2)), spheres)
    assert main(["verify", str(spheres), "--out", str(tmp_path / "v.nc"), "--refine"]) != 0
    assert "--refine is for ellipse and ellipsoid packings" in capsys.readouterr().err
    assert main(["verify", str(spheres), "--out", str(tmp_path / "v.nc"), "--ascent-max-particles", "10"]) != 0
    assert "--ascent-max-particles is for ellipse and ellipsoid packings" in capsys.readouterr().err
    assert main(["verify", str(DATA / "mm_n80_seed2_slow_p1e12.nc"), "--out", str(tmp_path / "v.nc"),
                 "--delta", "gaps", "--ascent-max-particles", "10"]) != 0
    assert "--ascent-max-particles applies with --refine only" in capsys.readouterr().err


def test_newton_step_is_solved_to_round_off():
    """The Newton step cancels the gaps to their round-off. A gap is computed from a separation
    x_j + L n - x_i of centres in a cell of side L, so it carries an error of a few eps L (measured
    by the same pairs taken in the other order, j -> i, whose Perram-Wertheim gap is the same
    exactly). The sparse LU's backward error is relative to the whole KKT system, dominated by the
    forces: without iterative refinement it left 6.6e-14 a in the gaps of this packing (2.9e-12 a
    at N = 1000, above the tolerance), with it 3.8e-15 a."""
    packing = _packing("mm_n80_seed2_slow_p1e12")
    res = verify_ellipsoids(packing, delta="gaps")
    a = float(np.min(packing.shape.semiaxes))
    floor = 8 * np.finfo(float).eps * float(np.max(np.abs(packing.lattice))) / a  # 2e-14
    ref = refine_jamming_point(packing, res, tol=floor)  # (without refinement: 20 steps at 5-10e-14)
    pairs = ellipsoid_contacts(ref.packing, 1e-9)
    forward = contacts_of_pairs(ref.packing, pairs.i, pairs.j, pairs.shift, positions=pairs.positions)
    backward = contacts_of_pairs(ref.packing, pairs.j, pairs.i, -pairs.shift, positions=pairs.positions)
    roundoff = np.abs(forward.zeta / forward.scale - backward.zeta / backward.scale).max() / a
    assert 0 < roundoff < floor  # the bound holds the measured round-off
    assert ref.converged and ref.gap[-1] < floor and ref.balance[-1] < 1e-12


def test_stationary_point_with_negative_forces_is_not_a_jamming_point():
    """Oblate spheroids (N = 40, LS to p = 1e12): with the contact tolerance widened to 2.06e-3,
    two pairs 1e-3 apart count as contacts. Holding them closed, Newton reaches a stationary point
    of the KKT equations (gaps and balance at round-off) whose self-stress pulls on exactly those
    two pairs (measured: 2 negative forces, down to -0.38 of the mean): it is not a jamming point
    (they would open as the particles grow). The active set drops them and Newton reaches the
    jamming point of the other contacts, every force positive."""
    packing = _packing("oblate_n40_slow_p1e12")
    res = verify_ellipsoids(packing, delta=2.06e-3)
    first = refine_jamming_point(packing, res, rounds=1)
    assert first.gap[-1] < 1e-12 and first.balance[-1] < 1e-12  # the KKT equations are solved
    assert not first.converged and first.negative == 2 and first.dropped == 0
    opened = res.network.gap[res.contacts_used] > 1e-6  # the pairs open in the LS packing
    assert opened.sum() == 2 and np.array_equal(first.forces < 0, opened)
    ref = refine_jamming_point(packing, res)
    assert ref.converged and ref.dropped == 2 and ref.negative == 0 and ref.overlaps == 0
    assert len(ref.forces) == len(first.forces) - 2 and ref.forces.min() > 0
    assert ref.gap[-1] < 1e-12 and ref.balance[-1] < 1e-12
    out = verify_at_jamming_point(packing, delta=2.06e-3)
    assert out.params["refined"] == 1 and out.params["refine_dropped"] == 2
    assert "2 contact(s) with negative forces at a stationary point left them" in out.params["refine_note"]


def test_collective_test_starts_the_refinement_when_the_local_test_loses_every_particle():
    """Self-dual alpha = 1.05, N = 100, LS to p = 1e12 (the full study's seed 1): the local test
    finds no particle with its own near self-stress (torques of order alpha - 1), so every
    particle looks like a rattler; the collective test of every particle has a strictly positive
    near self-stress, Newton converges from it (one pair added), and at the jamming point the full
    test (local test included) finds no rattler and second-order jamming of a hypostatic backbone
    (Donev 2006, Sec. 5.6)."""
    packing = _packing("self_dual_a1.05_n100_seed1_slow_p1e12")
    as_given = verify_ellipsoids(packing, delta="gaps")
    assert as_given.rattler.all() and as_given.verdict != Verdict.JAMMED
    out = verify_at_jamming_point(packing, delta="gaps")
    assert out.params["refined"] == 1 and "collective test of every particle" in out.params["refine_note"]
    assert (out.verdict, out.order) == (Verdict.JAMMED, "second") and not out.rattler.any()
    assert out.z_mean < 12 and out.params["refine_added"] >= 1


def test_a_diverging_newton_iteration_stops_instead_of_crashing():
    """Pairs up to 2e-2 apart held as contacts (oblate N = 40): the first Newton step is larger than
    a semiaxis (the network has no jamming point near). Unbounded, the next steps shrank the
    particles through zero (a crash on negative semiaxes) or exhausted memory; the iteration stops
    unconverged instead."""
    packing = _packing("oblate_n40_slow_p1e12")
    res = verify_ellipsoids(packing, delta=2e-2)
    ref = refine_jamming_point(packing, res)
    assert not ref.converged and ref.steps[-1] > MAX_STEP and ref.iterations == 1


def test_contacts_without_a_particle_to_hold_are_pinned_out_of_the_newton_system():
    """Prolate alpha = 1.02, N = 100, LS to p = 1e12 (the full study's seed 2): the local test loses
    every particle, so the collective test of all of them starts Newton. Three particles have no
    contact: their 3 x 5 dof are free in -K and A^T, and the first KKT matrix had exactly that null
    space (measured by SVD: rank deficiency 15, every null vector on those three particles;
    SuperLU: singular). Held fixed as rattlers (fewer than d + 1 contacts, Donev 2006,
    Sec. 4.4.3.1), they leave a regular system (smallest singular value 1.2e-5 of the largest) on
    which Newton converges quadratically to a stationary point (gaps and balance at round-off).
    That point is not a jamming point: one force is negative and 12 other pairs overlap there.
    With them the network diverges (a step of 2.8 semiaxes): the verdict is undetermined, and
    the note says why (not "singular")."""
    packing = _packing("prolate_a1.02_n100_seed2_slow_p1e12")
    res = verify_ellipsoids(packing, delta="gaps", local=False)
    used = res.contacts_used
    count = np.bincount(np.concatenate([res.network.i[used], res.network.j[used]]), minlength=100)
    assert (count == 0).sum() == 3 and count[count > 0].min() >= 4  # three particles without contacts
    first = refine_jamming_point(packing, res, rounds=1)
    assert first.pinned == 3 and first.iterations >= 3  # (without pinning: 0 steps, a singular system)
    assert first.gap[-1] < 1e-12 and first.balance[-1] < 1e-12  # the KKT equations are solved
    assert all(b <= 100 * a**2 + 1e-13 for a, b in zip(first.steps, first.steps[1:]))  # quadratically
    assert not first.converged and first.negative == 1 and first.overlaps == 12
    out = verify_at_jamming_point(packing, delta="gaps")
    assert out.params["refined"] == 0 and out.params["refine_pinned"] == 3
    assert "diverged" in out.params["refine_note"] and "singular" not in out.params["refine_note"]
    assert (out.verdict, out.order) == (Verdict.UNDETERMINED, "undetermined")
    ds = out.to_dataset()
    assert ds.attrs["verdict"] == int(Verdict.UNDETERMINED) and ds.attrs["order"] == "undetermined"


def test_a_singular_newton_system_gives_no_step():
    """An exactly singular KKT matrix (SuperLU raises RuntimeError) gives NaNs, on which Newton
    stops unconverged, instead of an exception from the verifier."""
    kkt = sp.csc_matrix(np.array([[1.0, 0.0], [0.0, 0.0]]))
    assert np.isnan(_solve(kkt, np.ones(2))).all()
    assert np.allclose(_solve(sp.csc_matrix(np.diag([1.0, 2.0])), np.ones(2)), [1.0, 0.5])


def test_the_next_network_drops_contacts_and_adds_only_overlapping_pairs():
    """Oblate N = 40 with two pairs 1e-3 apart held as contacts: at the stationary point of the
    first Newton run both are closed (touching to 1e-12) with negative forces. The next network
    is the current one without them; a rebuild from every touching pair (mu - 1 <= 1e-9) at that
    point would put them back and Newton would return to the same stationary point. Self-dual
    alpha = 1.05: at the jamming point of the LS contacts two pairs overlap; exactly those join."""
    packing = _packing("oblate_n40_slow_p1e12")
    res = verify_ellipsoids(packing, delta=2.06e-3)
    net, used = res.network, res.contacts_used
    pairs = net.i[used], net.j[used], net.shift[used]
    present = res.backbone | res.frozen
    first = refine_jamming_point(packing, res, rounds=1)
    assert first.negative == 2
    at = contacts_of_pairs(first.packing, *pairs)
    assert np.abs(at.gap[first.forces < 0]).max() < 1e-9  # the dropped pairs touch there
    no_walls = (np.zeros(0, np.int64), np.zeros(0, np.int64))
    after, walls, forces, out, new = _next_network(first.packing, pairs, no_walls, first.forces, present,
                                                   res.backbone, packing.overlap_tol)
    assert len(walls[0]) == 0
    assert (out, new) == (2, 0) and len(after[0]) == len(pairs[0]) - 2
    kept = {(int(i), int(j)) for i, j in zip(*after[:2])}
    assert not kept & {(int(pairs[0][c]), int(pairs[1][c])) for c in np.flatnonzero(first.forces < 0)}
    assert forces.min() > 0 and forces.sum() == pytest.approx(len(forces))
    # a stationary point with overlaps: the overlapping pairs join, the network stays
    packing = _packing("self_dual_a1.05_n100_slow_p1e12")
    res = verify_ellipsoids(packing, delta="gaps")
    net, used = res.network, res.contacts_used
    pairs = net.i[used], net.j[used], net.shift[used]
    one = refine_jamming_point(packing, res, rounds=1)
    assert one.converged and one.overlaps == 2
    after, _, forces, out, new = _next_network(one.packing, pairs, no_walls, one.forces, res.backbone | res.frozen,
                                               res.backbone, packing.overlap_tol)
    assert (out, new) == (0, 2) and np.array_equal(after[0][:-2], pairs[0])
    assert (contacts_of_pairs(one.packing, *(p[-2:] for p in after)).gap < -packing.overlap_tol).all()


# ------------------------------------------------------------------------------ flat hard walls
def _ellipse_in_a_square(theta, centre, factor, side=4.0):
    from hardpack.geometry.boundaries import HardWalls
    from hardpack.geometry.packing import Packing
    from hardpack.geometry.shapes import Ellipsoids

    return Packing(np.array([centre]), lattice=np.eye(2) * side, boundary=HardWalls((0, 1)),
                   shape=Ellipsoids(np.array([[2.0 * factor, 1.0 * factor]]), np.array([theta])))


def test_newton_between_walls_reaches_the_exact_jamming_point_of_an_ellipse_in_a_square():
    """An ellipse of semiaxes 2f and f in a square box of side L, touching all four walls: its
    widths are 2 f sqrt(a^2 cos^2 + b^2 sin^2) and 2 f sqrt(a^2 sin^2 + b^2 cos^2), the larger of
    which is smallest at 45 degrees, so the jamming point is the centre of the box, theta = pi/4
    and f = L / sqrt(2 (a^2 + b^2)) (a = 2, b = 1). Newton starts 1.1 degrees off, 1e-3 off centre
    and 3 % smaller, and lands there to round-off, quadratically."""
    side = 4.0
    exact = side / np.sqrt(2.0 * (4.0 + 1.0))
    start = _ellipse_in_a_square(np.pi / 4 + 0.02, [2.001, 1.999], 0.97 * exact, side)
    res = verify_ellipsoids(start, delta=0.05)
    assert res.network.n_wall_contacts == 4 and res.contacts_used.all()
    ref = refine_jamming_point(start, res)
    assert ref.converged and ref.overlaps == 0 and ref.iterations <= 4
    assert all(b <= 100 * a**2 + 1e-13 for a, b in zip(ref.gap, ref.gap[1:]))  # quadratically
    end = ref.packing
    np.testing.assert_allclose(end.positions, [[2.0, 2.0]], atol=1e-12)
    assert float(end.shape.orientations[0]) == pytest.approx(np.pi / 4, abs=1e-12)
    np.testing.assert_allclose(end.shape.semiaxes, [[2.0 * exact, exact]], rtol=1e-12)
    assert 1.0 + ref.size_change == pytest.approx(1.0 / 0.97, rel=1e-12)
    np.testing.assert_allclose(ref.forces, 1.0, rtol=1e-9)  # by symmetry, four equal wall forces
    # four contacts on three degrees of freedom: an exact (not near) self-stress already at the
    # start, which is first-order rigid, so the verdict needs no refinement
    out = verify_at_jamming_point(start, delta=0.05)
    assert out.verdict == Verdict.JAMMED and out.order == "first" and out.params["refined"] == 0


def test_newton_between_walls_refines_a_compressed_ellipse_packing_to_a_jamming_point():
    """30 ellipses LS-compressed in a closed box to p = 1e10: the default contact tolerance misses
    three contacts, with delta = 1e-8 the packing as given is second-order jammed with a near
    self-stress. Newton reaches the jamming point of its contacts; checked there independently of
    the Newton system: every contact of the network (18 with walls) touches to 1e-12 of a semiaxis
    (the gaps recomputed by the contact search, walls by the particles' extents), nothing overlaps
    or crosses a wall, and the verifier's self-stress balances the force and torque on every
    particle (computed from the contact points, a wall acting on its particle only)."""
    packing = _packing("ellipses_box_n30_seed1_p1e10")
    out = verify_at_jamming_point(packing, delta=1e-8)
    assert out.params["refined"] == 1 and out.verdict == Verdict.JAMMED and out.order == "second"
    note = out.params["refine_note"]
    assert "Newton converged" in note and out.params["refine_iterations"] <= 5
    res = verify_ellipsoids(packing, delta=1e-8)
    ref = refine_jamming_point(packing, res)
    end = ref.packing
    assert end.overlap_report(1e-12).n_overlapping == 0 and end.containment_report(1e-12).n_outside == 0
    net = ellipsoid_contacts(end, 1e-6)
    assert net.n_wall_contacts == res.network.subset(res.contacts_used).n_wall_contacts == 18
    assert np.abs(net.gap).max() < 1e-12
    at = verify_ellipsoids(end, delta=1e-9)
    f, net = at.contact_forces, at.network
    assert (f[at.contacts_used] > 0).all()
    pair = ~net.is_wall
    force, torque = np.zeros((30, 2)), np.zeros(30)

    def cross(r, u):
        return r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0]

    np.add.at(force, net.i, -f[:, None] * net.normal)
    np.add.at(force, net.j[pair], f[pair, None] * net.normal[pair])
    np.add.at(torque, net.i, cross(net.lever_i, -f[:, None] * net.normal))
    np.add.at(torque, net.j[pair], cross(net.lever_j[pair], f[pair, None] * net.normal[pair]))
    assert np.abs(force).max() < 1e-10 * f.max() and np.abs(torque).max() < 1e-10 * f.max()


def test_newton_between_walls_tracks_wall_contacts_by_particle_and_wall():
    """contacts_of_pairs appends the named flat-wall contacts with the gaps of ellipsoid_contacts and
    refuses them where the boundary has no such wall."""
    packing = _packing("ellipses_box_n30_seed1_p1e10")
    near = ellipsoid_contacts(packing, 1e-6)
    on_wall = near.is_wall
    given = contacts_of_pairs(packing, near.i[~on_wall], near.j[~on_wall], near.shift[~on_wall],
                              positions=near.positions, walls=(near.i[on_wall], near.wall[on_wall]))
    np.testing.assert_allclose(given.zeta, near.zeta, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(given.wall, near.wall)
    with pytest.raises(InvalidInputError, match="need a packing with walls"):
        contacts_of_pairs(_packing("oblate_n40_slow_p1e12"), [0], [1], [[0, 0, 0]], walls=([0], [0]))
    with pytest.raises(InvalidInputError, match="axis without walls"):
        contacts_of_pairs(packing, [0], [1], [[0, 0]], walls=([0], [4]))


# ------------------------------------------------------------------------- spherical containers
def _ellipse_and_two_disks():
    """The exact jamming point of an ellipse (semiaxes 0.8, 0.2) lying like a chord below the
    centre of a unit circle and touching it at both tips, with two equal disks above it, each
    touching the ellipse, the other disk and the circle. With the ellipse centre at (0, -rho) and
    the disks at (+-X, Y), radius r: the farthest point of the ellipse from the centre is at 1, X = r,
    |(X, Y)| = 1 - r and the distance of (X, Y) from the ellipse is r; the distances are found
    on the parametrised ellipse by a bounded scalar search, independently of the contact code."""
    from scipy.optimize import fsolve, minimize_scalar

    a, b = 0.8, 0.2

    def search(f, lo, hi):
        return minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 1e-14}).fun

    def equations(v):
        rho, x, y, r = v
        far = -search(lambda t: -np.hypot(a * np.cos(t), -rho + b * np.sin(t)), -np.pi / 2, 0.0)
        near = search(lambda t: np.hypot(x - a * np.cos(t), y + rho - b * np.sin(t)), 0.0, np.pi / 2)
        return [far - 1.0, x - r, np.hypot(x, y) - (1.0 - r), near - r]

    solution = fsolve(equations, [0.55, 0.3, 0.2, 0.3], xtol=1e-12)
    assert np.abs(equations(solution)).max() < 1e-14
    return a, b, *solution


def _in_circle(a, b, rho, x, y, r, factor=1.0, moved=0.0, turned=0.0):
    from hardpack.geometry.boundaries import SphericalContainer
    from hardpack.geometry.packing import Packing
    from hardpack.geometry.shapes import Ellipsoids

    centre = np.array([1.5, 1.5])
    return Packing(centre + np.array([[0.0, -rho], [-x, y], [x, y]]) + moved, lattice=np.eye(2) * 3.0,
                   boundary=SphericalContainer(tuple(centre), 1.0), allow_overlap=True,
                   shape=Ellipsoids(factor * np.array([[a, b], [r, r], [r, r]]), np.array([turned, 0.0, 0.0])))


def test_newton_in_a_container_reaches_the_exact_jamming_point_of_an_ellipse_touching_at_both_tips():
    """The ellipse and two disks of _ellipse_and_two_disks, 0.1 % smaller, moved by 1e-4 and the
    ellipse turned by 1e-3: seven contacts (the ellipse's two tips on the container) on six
    degrees of freedom besides the rotation about the centre. Newton tracks both tips as two
    contacts and lands on the exact configuration (up to that rotation) to round-off,
    quadratically; by the mirror symmetry both tips carry the same force."""
    a, b, rho, x, y, r = exact = _ellipse_and_two_disks()
    assert r > 0.4 and 0 < y < 1  # the solution of the sketch, not another root
    rng = np.random.default_rng(1)
    start = _in_circle(*exact, factor=0.999, moved=1e-4 * rng.standard_normal((3, 2)), turned=1e-3)
    assert start.overlap_report(1e-12).n_overlapping == 0 and start.containment_report(1e-12).n_outside == 0
    res = verify_ellipsoids(start, delta=0.01)
    net = res.network
    assert res.contacts_used.all() and list(net.i[net.is_wall]) == [0, 0, 1, 2]
    ref = refine_jamming_point(start, res)
    assert ref.converged and ref.overlaps == 0 and ref.iterations <= 4
    assert all(g <= 100 * f**2 + 1e-13 for f, g in zip(ref.gap, ref.gap[1:]))  # quadratically
    end = ref.packing
    rel = end.positions - 1.5
    turn = np.arctan2(rel[0, 1], rel[0, 0]) + np.pi / 2  # the trivial rotation about the centre
    back = np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    np.testing.assert_allclose(rel @ back.T, [[0.0, -rho], [-x, y], [x, y]], atol=1e-13)
    assert float(end.shape.orientations[0]) == pytest.approx(turn, abs=1e-13)
    np.testing.assert_allclose(end.shape.semiaxes, [[a, b], [r, r], [r, r]], rtol=1e-13)
    assert 1.0 + ref.size_change == pytest.approx(1.0 / 0.999, rel=1e-13)
    tips = ref.forces[-4:-2]  # the walls follow the pairs, the ellipse's first
    assert (ref.forces > 0).all() and tips[0] == pytest.approx(tips[1], rel=1e-10)


def test_container_contacts_are_tracked_by_their_tips():
    """A centred ellipse of semiaxes 1 and 0.3, turned by 0.4 rad, in a circle of radius 1.01
    touches it near both tips, 0.01 away: contacts_of_pairs returns, for each given body-frame
    tip, the contact at that tip (the points c +- R^T (1, 0)), with the gaps of ellipsoid_contacts;
    a container contact without its tip is refused."""
    from hardpack.geometry.boundaries import SphericalContainer
    from hardpack.geometry.packing import Packing
    from hardpack.geometry.shapes import Ellipsoids

    theta = 0.4
    packing = Packing(np.array([[1.5, 1.5]]), lattice=np.eye(2) * 3.0, boundary=SphericalContainer((1.5, 1.5), 1.01),
                      shape=Ellipsoids(np.array([[1.0, 0.3]]), np.array([theta])))
    axis = np.array([np.cos(theta), np.sin(theta)])
    for sign in (1.0, -1.0):
        net = contacts_of_pairs(packing, [], [], np.zeros((0, 2)), walls=([0], [0], [[0.9 * sign, 0.1]]))
        np.testing.assert_allclose(net.lever_i, [sign * axis], atol=1e-12)
        np.testing.assert_allclose(net.gap, [0.01], atol=1e-12)
    near = ellipsoid_contacts(packing, 0.02)
    np.testing.assert_allclose(near.gap, [0.01, 0.01], atol=1e-12)
    with pytest.raises(InvalidInputError, match="tip"):
        contacts_of_pairs(packing, [], [], np.zeros((0, 2)), walls=([0], [0]))


@pytest.mark.parametrize("name, n_wall", [("ellipses_container_n20_seed1_p1e10", 10),
                                           ("mm_container_n24_seed1_p1e10", 18)])
def test_newton_in_a_container_refines_a_compressed_packing_to_a_jamming_point(name, n_wall):
    """20 ellipses and 24 M&M spheroids LS-compressed in a spherical container to p = 1e10:
    second-order jammed with a near self-stress as given; Newton reaches the jamming point of
    their contacts, checked there independently of the Newton system: every contact touches to
    1e-12 of a semiaxis by the contact search, nothing overlaps or leaves the container, and the
    verifier's self-stress balances the force and torque on every particle."""
    packing = _packing(name)
    out = verify_at_jamming_point(packing, delta=1e-8)
    assert out.params["refined"] == 1 and out.verdict == Verdict.JAMMED and out.order == "second"
    assert "Newton converged" in out.params["refine_note"] and out.params["refine_iterations"] <= 5
    ref = refine_jamming_point(packing, verify_ellipsoids(packing, delta=1e-8))
    end = ref.packing
    assert end.overlap_report(1e-12).n_overlapping == 0 and end.containment_report(1e-12).n_outside == 0
    net = ellipsoid_contacts(end, 1e-6)
    assert net.n_wall_contacts == n_wall and np.abs(net.gap).max() < 1e-12
    at = verify_ellipsoids(end, delta=1e-9)
    f, net = at.contact_forces, at.network
    assert (f[at.contacts_used] > 0).all() and net.n_wall_contacts == n_wall
    n, d = packing.n_particles, packing.dim
    pair = ~net.is_wall

    def torque_of(r, u):  # r x u: a scalar in 2D, a vector in 3D
        return (r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0])[:, None] if d == 2 else np.cross(r, u)

    force, torque = np.zeros((n, d)), np.zeros((n, 1 if d == 2 else 3))
    np.add.at(force, net.i, -f[:, None] * net.normal)
    np.add.at(force, net.j[pair], f[pair, None] * net.normal[pair])
    np.add.at(torque, net.i, torque_of(net.lever_i, -f[:, None] * net.normal))
    np.add.at(torque, net.j[pair], torque_of(net.lever_j[pair], f[pair, None] * net.normal[pair]))
    assert np.abs(force).max() < 1e-10 * f.max() and np.abs(torque).max() < 1e-10 * f.max()
