"""The diluted-MRJ protocol of Torquato & Jiao (2010, Sec. VI): removal, re-jamming, checkpoints, summary."""

import numpy as np
import pytest

from hardpack import InvalidInputError
from hardpack.distributions import monodisperse
from hardpack.initial import random_packing
from hardpack.slp import Bounds, diluted_summary, run_diluted, run_slp
from hardpack.slp.diluted import removal_count, remove_random

MRJ = Bounds(0.1, 0.1, 0.5)  # Table I settings (Torquato & Jiao 2010, Sec. V.A), gamma = 1.5 D


@pytest.fixture(scope="module")
def mrj():
    """A 3D SLP MRJ packing of 64 spheres from a dilute start (phi ~ 0.63, 108 LPs, ~5 s)."""
    result = run_slp(random_packing(64, 3, monodisperse(), 0.05, seed=1), 1.5, MRJ)
    assert result.converged
    return result.packing


@pytest.fixture(scope="module")
def diluted(mrj):
    """Two rounds removing round(0.03 * 64) = 2 spheres each."""
    return run_diluted(mrj, fraction=0.03, rounds=2, seed=1, alpha=1.5, bounds=MRJ)


def test_each_round_removes_the_configured_number_and_rejams(mrj, diluted):
    """Round r holds 64 - 2 r spheres, a subset of the previous round's; the removal alone lowers
    phi by exactly 2 sphere volumes (same cell), and the SLP re-jamming (converged) raises it again
    from there without overlaps."""
    previous, prev_phi = np.arange(64), mrj.phi
    for r, rnd in enumerate(diluted, start=1):
        n_before = previous.size
        assert rnd.n_removed == 2 and rnd.packing.n_particles == 64 - 2 * r
        assert np.array_equal(rnd.start_index, np.sort(rnd.start_index))
        assert set(rnd.start_index) < set(previous)
        assert rnd.phi_diluted == pytest.approx(prev_phi * (n_before - 2) / n_before, rel=1e-12)
        assert rnd.converged and rnd.n_steps > 1
        assert rnd.packing.phi > rnd.phi_diluted
        assert rnd.packing.overlap_report().n_overlapping == 0
        previous, prev_phi = rnd.start_index, rnd.packing.phi


def test_removal_is_seeded_and_leaves_the_rest_in_place(mrj):
    """The same generator state removes the same spheres; the kept ones do not move."""
    a, keep_a = remove_random(mrj, 5, np.random.default_rng((3, 1)))
    b, keep_b = remove_random(mrj, 5, np.random.default_rng((3, 1)))
    _, keep_c = remove_random(mrj, 5, np.random.default_rng((3, 2)))
    assert np.array_equal(keep_a, keep_b) and keep_a.size == 59 and not np.array_equal(keep_a, keep_c)
    np.testing.assert_array_equal(a.positions, mrj.positions[keep_a])
    np.testing.assert_array_equal(a.lattice, mrj.lattice)


def test_a_killed_run_resumes_and_ends_identically(tmp_path, monkeypatch, mrj, diluted):
    """Killed during the second round's re-jamming (after round 1 was checkpointed and with the
    round's SLP checkpointed after every LP), the run started again skips round 1 and the LPs
    already done, and ends with the packings of the uninterrupted run, bit for bit; both
    checkpoints are removed at the end, and one of another run (other seed) is refused."""
    import hardpack.slp.driver as driver

    solve = driver.solve_step
    n_round1 = diluted[0].n_steps
    kill_at = n_round1 + 5
    calls = []

    def dying(*a, **k):
        calls.append(1)
        if len(calls) > kill_at:
            raise KeyboardInterrupt  # the job is killed
        return solve(*a, **k)

    ckpt = tmp_path / "diluted.ckpt"
    args = dict(fraction=0.03, rounds=2, seed=1, alpha=1.5, bounds=MRJ, checkpoint=ckpt, checkpoint_interval=0.0)
    monkeypatch.setattr(driver, "solve_step", dying)
    with pytest.raises(KeyboardInterrupt):
        run_diluted(mrj, **args)
    assert ckpt.exists() and (tmp_path / "diluted.ckpt.slp").exists()
    with pytest.raises(InvalidInputError, match="different run"):
        run_diluted(mrj, **{**args, "seed": 2})
    counted = []
    monkeypatch.setattr(driver, "solve_step", lambda *a, **k: counted.append(1) or solve(*a, **k))
    resumed = run_diluted(mrj, **args)
    assert len(counted) == sum(r.n_steps for r in diluted) - kill_at  # nothing done twice
    assert not ckpt.exists() and not (tmp_path / "diluted.ckpt.slp").exists()
    for ours, whole in zip(resumed, diluted, strict=True):
        np.testing.assert_array_equal(ours.packing.positions, whole.packing.positions)
        np.testing.assert_array_equal(ours.packing.lattice, whole.packing.lattice)
        np.testing.assert_array_equal(ours.start_index, whole.start_index)
        assert (ours.n_steps, ours.phi_diluted) == (whole.n_steps, whole.phi_diluted)


@pytest.mark.parametrize(
    "kwargs, message",
    [(dict(fraction=0.0), "fraction must be in"),
     (dict(fraction=0.005), "removes none per round"),
     (dict(fraction=0.3, rounds=4), "leave -12 of 64"),
     (dict(rounds=0), "rounds must be a positive integer"),
     (dict(seed=-1), "seed must be a non-negative integer"),
     (dict(seed=True), "seed must be a non-negative integer, got True"),
     (dict(seed=1.5), "seed must be a non-negative integer, got 1.5")],
)
def test_bad_settings_are_refused(mrj, kwargs, message):
    args = {**dict(fraction=0.03, rounds=2, seed=1, alpha=1.5, bounds=MRJ), **kwargs}
    with pytest.raises(InvalidInputError, match=message):
        run_diluted(mrj, **args)


def test_removal_count_follows_the_start_size():
    """f_s N_0 rounded: the paper's 0.1 % of N = 1000 is one sphere, 2.5 % is 25."""
    assert removal_count(1000, 0.001, 10) == 1 and removal_count(1000, 0.025, 10) == 25
    assert removal_count(64, 0.03, 2) == 2


def test_cli_rounds_and_summary_over_seed_and_round(tmp_path, mrj):
    """`hardpack slp-dilute` writes one packing per round (its round, the spheres removed so far,
    each sphere's index in the start, no jamming claim); the summary puts the start (round 0)
    and the rounds on a (seed, round) grid with phi without the verifier's rattlers equal to
    phi (N - N_rattlers) / N for equal spheres, and refuses an incomplete grid."""
    from hardpack.cli import main
    from hardpack.io import load_dataset, load_packing, save_packing, write_dataset
    from hardpack.jamming import verify

    start = tmp_path / "mrj.nc"
    save_packing(mrj, start, attrs={"seed": 1, "ensemble": "mono3d"})
    out = tmp_path / "diluted"
    assert main(["slp-dilute", "--init", str(start), "--out-dir", str(out), "--fraction", "0.03",
                 "--rounds", "2", "--seed", "1"]) == 0
    packings = [start, out / "round1.nc", out / "round2.nc"]
    verdicts = []
    for path in packings:
        verdict = verify(load_packing(path), seed=1).to_dataset()
        verdict.attrs["source"] = str(path)
        verdicts.append(tmp_path / f"jamming_{path.name}")
        write_dataset(verdict, verdicts[-1])
    attrs = load_dataset(packings[2], kind="packing").attrs
    assert (attrs["dilution_round"], attrs["n_removed"], attrs["n_removed_total"], attrs["N"]) == (2, 2, 4, 60)
    assert attrs["ensemble"] == "mono3d" and attrs["N_start"] == 64
    assert not {"jamming_claim", "verdict", "strict", "collective"} & set(attrs)
    index = load_dataset(packings[2], kind="packing")["start_index"].values
    assert index.size == 60 and np.unique(index).size == 60 and index.max() < 64

    summary = diluted_summary(packings, verdicts)
    assert summary["phi"].dims == ("seed", "round")
    assert summary["round"].values.tolist() == [0, 1, 2] and summary["seed"].values.tolist() == [1]
    assert summary["n_removed"].values.tolist() == [[0, 2, 4]]
    assert summary["N"].values.tolist() == [[64, 62, 60]]
    for k, path in enumerate(verdicts):
        v = load_dataset(path, kind="jamming")
        n = v.attrs["N"]
        phi = float(summary["phi"][0, k])
        assert float(summary["phi_no_rattlers"][0, k]) == pytest.approx(phi * (n - v.attrs["n_rattlers"]) / n, rel=1e-12)
        assert float(summary["z_mean"][0, k]) == v.attrs["z_mean"] and int(summary["strict"][0, k]) == v.attrs["strict"]
    assert np.isnan(summary["phi_diluted"][0, 0]) and summary["phi_diluted"][0, 1] < summary["phi"][0, 0]
    assert np.all(np.isfinite(summary["T"].values))
    other, other_verdict = _store_other(tmp_path, mrj)
    with pytest.raises(InvalidInputError, match="no packing for"):
        diluted_summary(packings[:2] + [other], verdicts[:2] + [other_verdict])
    with pytest.raises(InvalidInputError, match="judges"):
        diluted_summary(packings, verdicts[::-1])


def _store_other(tmp_path, mrj):
    """A packing of seed 2, round 1 with its verdict: the grid then misses (1, 2), (2, 0), (2, 2)."""
    from hardpack.io import save_packing, write_dataset
    from hardpack.jamming import verify

    path, verdict_path = tmp_path / "other.nc", tmp_path / "jamming_other.nc"
    save_packing(mrj, path, attrs={"seed": 2, "dilution_round": 1})
    verdict = verify(mrj, seed=2).to_dataset()
    verdict.attrs["source"] = str(path)
    write_dataset(verdict, verdict_path)
    return path, verdict_path
