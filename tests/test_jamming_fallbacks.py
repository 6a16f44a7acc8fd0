"""Numerical fallbacks and undecidable tests are recorded in the verdict, never silent.

- HiGHS retried with its default tolerances (1e-7 instead of 1e-10): counted in
  ``JammingResult.fallbacks``, its dataset and the file ``hardpack verify`` writes;
- a strict LP's strain with Tr eps > 0: made traceless only within the LP's accuracy (1e-10 of
  the box); beyond, the test is undetermined with the reason (Eq. 4.17 is violated);
- a sequential step that round-off keeps overlapping (or a non-finite LP motion): the test is
  undetermined with the reason, not "jammed";
- every particle a rattler: no backbone, not jammed, and no collective or strict LP solved.
"""

from __future__ import annotations

import argparse

import numpy as np
import pytest
import scipy.optimize

from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.io import load_dataset, save_packing
from hardpack.jamming import cli, contact_network, highs, lp, sequential, verify, workingset
from hardpack.jamming.highs import recording_fallbacks


def _shrunk(p: Packing, s: float) -> Packing:
    return p.replace(radii=p.radii * (1 - s))


# ---------------------------------------------------------------- HiGHS at default tolerances
@pytest.fixture
def tight_tolerances_fail(monkeypatch):
    """HiGHS 'fails' (status 4, numerical trouble) whenever it runs at the tight tolerances, so
    every LP through solve_lp ends at HiGHS's defaults."""
    real = scipy.optimize.linprog

    def linprog(*args, options=None, **kwargs):
        if (options or {}).get("primal_feasibility_tolerance") == highs.HIGHS_OPTIONS["primal_feasibility_tolerance"]:
            return scipy.optimize.OptimizeResult(status=4, message="numerical trouble (test)")
        return real(*args, options=options, **kwargs)

    monkeypatch.setattr(highs, "linprog", linprog)


def test_default_tolerance_retry_is_recorded(tight_tolerances_fail):
    r = verify(lattice_packing("kagome", (1, 1)), seed=1)  # local LPs through HiGHS
    assert r.category == "locally jammed"
    count = r.fallbacks["lp_default_tolerances"]
    assert count >= 1
    assert r.to_dataset().attrs["fallback_lp_default_tolerances"] == count
    assert "numerical fallback lp_default_tolerances" in r.summary()


def test_no_fallback_is_recorded_as_zero():
    r = verify(lattice_packing("kagome", (1, 1)), seed=1)
    attrs = r.to_dataset().attrs
    assert all(attrs[f"fallback_{name}"] == 0 for name in highs.FALLBACKS)


def test_verify_cli_writes_the_fallbacks(tmp_path, tight_tolerances_fail):
    src, out = tmp_path / "kagome.nc", tmp_path / "verdict.nc"
    save_packing(lattice_packing("kagome", (1, 1)), src)
    parser = argparse.ArgumentParser(prog="hardpack")
    cli.register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["verify", str(src), "--out", str(out), "--seed", "1"])
    assert args.func(args) == 0
    assert load_dataset(out, kind="jamming").attrs["fallback_lp_default_tolerances"] >= 1


def test_fallbacks_of_sequences_in_worker_processes_are_recorded(tight_tolerances_fail):
    """A sequential test records the fallbacks of its loading sequences (their own record,
    which a worker process would send back with the sequence)."""
    p = _shrunk(lattice_packing("square", (2, 1)), 1e-3)
    r = verify(p, delta=0.2, method="sequential", tests=("collective",), seed=1, threshold=1e-2,
               contact_delta=2e-3)
    assert r.collective_test.fallbacks["lp_working_set_to_highs"] == 0
    assert r.fallbacks["lp_default_tolerances"] >= 1  # the local test's LPs


# ---------------------------------------------------------------- Tr eps > 0
@pytest.fixture
def trace_excess(monkeypatch):
    """The working set's solutions get their diagonal strain raised by ``excess[0]`` each
    (Tr eps = d excess), as a solver outside its tolerance would return."""
    excess = [0.0]
    real = lp.solve_working_set

    def solve(g, h, c, upper, *, boxed=None, **kwargs):
        sol = real(g, h, c, upper, boxed=boxed, **kwargs)
        if sol is not None and boxed is not None and boxed.size:
            x = sol.x.copy()
            d = {1: 1, 3: 2, 6: 3}[boxed.size]
            x[boxed[:d]] += excess[0]
            sol = workingset.WorkingSetSolution(x, sol.forces, sol.objective, sol.basis, sol.working, sol.rounds)
        return sol

    monkeypatch.setattr(lp, "solve_working_set", solve)
    return excess


def _strict_motion(box=0.05):
    p = lattice_packing("triangular", (2, 2))
    net = contact_network(p, 0.1)
    rng = np.random.default_rng(0)
    moving = np.ones(p.n_particles, bool)
    return lp.solve_motion(net, moving, lp.random_load(rng, moving, 2),
                           strain_load=lp.random_strain_load(rng, 2, 2.0), box=box, cell_length=2.0)


def test_trace_within_the_lp_accuracy_is_made_exact(trace_excess):
    trace_excess[0] = 0.1 * lp.TRACE_TOLERANCE * 0.05
    mot = _strict_motion()
    assert mot.solver == "working-set" and np.trace(mot.strain) <= 0.0


@pytest.fixture
def every_trace_too_large(monkeypatch):
    """A negative accuracy: every strict solution, HiGHS's included, breaks Tr eps <= 0 by more."""
    monkeypatch.setattr(lp, "TRACE_TOLERANCE", -1.0)


def test_a_working_set_trace_beyond_the_lp_accuracy_is_solved_again_by_highs(trace_excess):
    """The working set's round-off (1e-9 of the box in a rotated HCP cell) is not the LP's answer:
    HiGHS solves that LP again, Tr eps <= 0 holds, and the fallback is counted."""
    trace_excess[0] = 1e-6 * 0.05
    with recording_fallbacks() as counts:
        mot = _strict_motion()
    assert mot.solver == "highs" and np.trace(mot.strain) <= lp.TRACE_TOLERANCE * 0.05
    assert counts["lp_volume_to_highs"] == 1


def test_a_highs_trace_beyond_the_lp_accuracy_is_refused(every_trace_too_large):
    with pytest.raises(lp.VolumeIncrease, match="highs solution .*Tr eps = .* volume constraint"):
        _strict_motion()


def test_trace_beyond_the_lp_accuracy_leaves_the_strict_test_undetermined(every_trace_too_large):
    p = _shrunk(lattice_packing("triangular", (2, 2)), 1e-4)
    r = verify(p, delta=0.2, method="sequential", seed=2, threshold=1e-2, contact_delta=1e-3)
    assert r.collective and r.strict is None
    assert "volume constraint" in r.undetermined["strict"]
    assert r.category == "collectively jammed; strict jamming undetermined"
    attrs = r.to_dataset().attrs
    assert attrs["strict"] == -2 and "volume constraint" in attrs["strict_undetermined"]


# ---------------------------------------------------------------- steps that cannot be taken
def test_advance_gives_up_on_a_step_that_always_overlaps():
    """A non-finite motion makes every halved step an invalid packing: no step (None), where the
    packing used to come back unmoved with tau = 0, i.e. as if the load were supported."""
    p = lattice_packing("square", (2, 1))
    net = contact_network(p, 0.1)
    disp = np.full((2, 2), np.nan)
    assert sequential._advance(p, net, disp, None, 0.01) is None


def test_a_sequence_that_cannot_step_is_undetermined(monkeypatch):
    monkeypatch.setattr(sequential, "_advance", lambda *args: None)
    p = _shrunk(lattice_packing("square", (2, 1)), 1e-3)
    r = verify(p, delta=0.2, method="sequential", tests=("collective",), seed=1, threshold=1e-2,
               contact_delta=2e-3)
    assert r.collective is None and "halvings" in r.undetermined["collective"]
    assert r.category == "locally jammed; collective jamming undetermined"
    assert "collective test undetermined" in r.summary()


def test_a_sequence_beyond_the_threshold_settles_the_verdict_despite_another_undetermined(monkeypatch):
    """Sequence 1 cannot step, sequence 2 slides the square rows: not jammed (determined)."""
    real, calls = sequential._advance, [0]

    def advance(*args):
        calls[0] += 1
        return None if calls[0] == 1 else real(*args)

    monkeypatch.setattr(sequential, "_advance", advance)
    p = _shrunk(lattice_packing("square", (2, 1)), 1e-3)
    r = verify(p, delta=0.2, method="sequential", tests=("collective",), seed=1, threshold=1e-2,
               contact_delta=2e-3)
    assert r.collective is False and not r.undetermined
    assert len(r.collective_test.steps) == 2


# ---------------------------------------------------------------- no backbone
@pytest.mark.parametrize("method", ["ideal", "sequential"])
def test_all_rattlers_no_backbone_and_no_lp(method):
    """A dilute packing: every particle is a rattler, nothing is jammed; the collective and
    strict tests need no LP (the sequential strict test used to shear the empty cell)."""
    p = _shrunk(lattice_packing("triangular", (4, 4)), 0.2)
    r = verify(p, method=method, seed=1)
    assert r.rattler.all() and not r.local and r.category == "not jammed"
    assert r.collective is False and r.strict is False
    assert r.collective_test.n_lp == 0 and r.strict_test.n_lp == 0
    attrs = r.to_dataset().attrs
    assert attrs["n_rattlers"] == p.n_particles and attrs["n_backbone"] == 0
    assert "no backbone" in r.summary()
