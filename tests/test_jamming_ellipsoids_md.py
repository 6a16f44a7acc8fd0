"""Jamming tests of ellipse and ellipsoid packings from the LS compression (Donev 2006, Secs. 5.2, 5.6).

The packings in tests/data were made by ``hardpack compress`` from the RSA starts of the smoke
study (N = 40, binary ellipses alpha = 1.5 and oblate spheroids alpha = 1.5, seed 1), growth rate
0.03 up to Z = 1e3, then the final rate given in the name ('slow' 1e-3, 'fast' 1e-2), to the reduced
pressure in the name. What the text says of such packings:

- they are near, not at, their jamming point: A f = 0 holds only approximately, with the smallest
  eigenvalue of A^T A 3-6 orders of magnitude below the next, its eigenvector strictly positive,
  and the packings second-order jammed (Sec. 5.6);
- fast particle expansion leaves packings whose torques are not balanced, translationally but not
  rotationally jammed (Sec. 5.9);
- contacts are defined by a tolerance on the gaps, which must separate contacts from near contacts
  (Sec. 5.2, ch. 9).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hardpack.io import dataset_to_packing, load_dataset
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import (
    APPROX_STRESS_GAP,
    approximate_stress,
    contact_delta_from_gaps,
    verify_ellipsoids,
)

DATA = Path(__file__).parent / "data"


def _packing(name):
    return dataset_to_packing(load_dataset(DATA / f"{name}.nc"), allow_overlap=True)


def test_slowly_compressed_ellipses_are_second_order_jammed():
    """p = 1e12 at the slow final rate: no pair within 1e-2 lies above the contacts; A f = 0 has
    no exact solution (the exact LP 5.9 is infeasible: 'not jammed' before the near self-stress of
    Sec. 5.6 was accepted) but a strictly positive near one, |A f| ~ 1e-5; hypostatic (Z = 5.6 < 6)
    and jammed at second order."""
    res = verify_ellipsoids(_packing("ellipses_n40_slow_p1e12"), delta="gaps")
    assert res.params["delta_ambiguous"] == 0 and 1e-10 < res.params["delta"] < 1e-3
    c = res.collective
    assert c.approx_stress is not None and c.approx_stress.min() > 0 and c.stress_residual < 1e-4
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert res.isostaticity_gap < 0 and c.n_floppy > 0 and c.n_stresses == 1
    assert not res.rattler.any()


def test_slowly_compressed_spheroids_are_second_order_jammed():
    """The same for oblate spheroids (5 dof each): Z = 9.6 < 10, jammed at second order."""
    res = verify_ellipsoids(_packing("oblate_n40_slow_p1e12"), delta="gaps")
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert res.z_mean < 10 and res.collective.approx_stress.min() > 0


def test_fast_compressed_ellipses_have_unbalanced_torques():
    """The fast final rate leaves no near self-stress (s_1 / s_2 of the balance-scaled A above
    10^-1.5): not jammed, decided at first order by the flex the LP finds."""
    packing = _packing("ellipses_n40_fast_p1e12")
    res = verify_ellipsoids(packing, delta="gaps")
    assert res.verdict == Verdict.NOT_JAMMED and res.order == "first"
    assert res.collective.approx_stress is None and res.collective.lp_flex


def test_unresolved_contacts_are_undetermined():
    """p = 1e5: the gaps of the contacts and the near contacts overlap (more than 1% of the contacts
    have a pair within a decade of any tolerance), so no verdict: undetermined, with the reason."""
    res = verify_ellipsoids(_packing("ellipses_n40_fast_p1e5"), delta="gaps")
    assert res.params["delta_ambiguous"] > 0.01 * res.network.n_contacts
    assert res.verdict == Verdict.UNDETERMINED and res.order == "undetermined"
    assert "contacts not resolved" in res.collective.reason


def test_contact_delta_from_gaps():
    """The tolerance sits where the fewest pairs lie within a decade of it, above the fewest
    contacts of a jammed packing (Z >= d + 1), in the middle of the longest such run; the search
    bound closes the range; a sparse tail of near contacts is counted, not a reason to fail."""
    gaps = np.concatenate([[1e-17], np.full(59, 1e-12), np.full(10, 1e-6)])  # N = 40, d = 2: 60 needed
    delta, ambiguous = contact_delta_from_gaps(gaps, 40, 2)
    assert delta == pytest.approx(1e-9, rel=0.15) and ambiguous == 0
    delta, ambiguous = contact_delta_from_gaps(gaps[:60], 40, 2)  # nothing above the contacts
    assert delta == pytest.approx(1e-7, rel=0.15) and ambiguous == 0
    tail = np.concatenate([gaps[:60], 10.0 ** np.arange(-10, -2.5, 0.5)])  # one pair every half decade
    delta, ambiguous = contact_delta_from_gaps(tail, 40, 2)
    assert ambiguous == 1 and 1e-12 < delta < 1e-10  # just above the contacts, before the tail
    assert np.isnan(contact_delta_from_gaps(gaps[:50], 40, 2)[0])


def test_near_stress_ignores_the_scale_of_the_torque_rows():
    """A near-sphere balance: force rows O(1), a torque row O(1e-3) that no positive F balances
    to its own scale. Unscaled, s_1 / s_2 would pass the gap; the scaled rows refuse it."""
    a = np.array([[1.0, -1.0, 0.0], [0.0, 1.0, -1.0], [1e-3, 2e-3, 0.5e-3]])  # rows: balance eqs
    at = a.T
    s = np.linalg.svd(a, compute_uv=False)
    assert s[-1] / s[-2] < APPROX_STRESS_GAP
    assert approximate_stress(at) is None
    near = approximate_stress(np.vstack([at[:, :2].T, [1e-3, 1e-3, -2e-3 + 1e-9]]).T)
    assert near is not None and near[0].min() > 0


@pytest.mark.slow
def test_near_sphere_ellipsoids_hypostatic_and_second_order_jammed(monkeypatch):
    """General ellipsoids near the sphere point (semiaxes 1 : 1.05^(1/2) : 1.05, N = 100, slow rate,
    p = 1e12): Z = 7.5 < 12 = 2 d_f, hypostatic, and jammed at second order (Donev 2006, Sec. 5.6:
    'indeed second-order jammed, even very close to the sphere point'). The local tests must see A
    at the jamming point of the whole packing's near self-stress: with each particle's exact local
    balance instead, every particle is a 'rattler' (near the sphere point the O(alpha - 1) torque
    rows make the local balance need negative forces at a finite pressure)."""
    from hardpack.jamming import second_order

    packing = _packing("self_dual_a1.05_n100_slow_p1e12")
    res = verify_ellipsoids(packing, delta="gaps")
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert res.z_mean < 12 and res.isostaticity_gap < 0 and not res.rattler.any()
    monkeypatch.setattr(second_order, "_global_near_stress", lambda *args: None)
    res = verify_ellipsoids(packing, delta="gaps")
    assert res.rattler.all() and res.verdict == Verdict.NOT_JAMMED


def test_cli_verifies_with_gaps_and_attributes(tmp_path, capsys):
    """``hardpack verify --delta gaps --attr alpha=1.5``: the verdict file carries the order that
    decided, the tolerance read off the gaps and the attribute; sphere packings refuse 'gaps'."""
    from hardpack.cli import main
    from hardpack.geometry.lattices import lattice_packing
    from hardpack.io import save_packing

    out = tmp_path / "verdict.nc"
    assert main(["verify", str(DATA / "ellipses_n40_slow_p1e12.nc"), "--out", str(out), "--delta", "gaps",
                 "--attr", "alpha=1.5", "--seed", "3"]) == 0
    ds = load_dataset(out)
    assert ds.attrs["order"] == "second" and ds.attrs["order_code"] == 2 and ds.attrs["jammed"] == 1
    assert ds.attrs["alpha"] == 1.5 and ds.attrs["delta_ambiguous"] == 0 and ds.attrs["seed"] == 3
    assert "decided at order: second" in capsys.readouterr().out
    spheres = tmp_path / "fcc.nc"
    save_packing(lattice_packing("fcc", 2), spheres)
    assert main(["verify", str(spheres), "--out", str(tmp_path / "v.nc"), "--delta", "gaps"]) != 0
    assert "--delta gaps is for ellipse and ellipsoid packings" in capsys.readouterr().err


def test_verdict_fractions_per_shape():
    """Fractions over the packings of each (beta, alpha): jammed, decided at first / second order
    or not at all, hypostatic; mean backbone Z with its standard error, rattler fraction."""
    import xarray as xr

    from hardpack.jamming.ellipsoid_verdicts import verdict_fractions

    summary = xr.Dataset(
        {"jammed": ("sample", [1.0, 0.0, 1.0, 1.0]), "order_code": ("sample", [2, 1, 0, 2]),
         "hypostatic": ("sample", [1, 1, 1, 0]), "z_mean": ("sample", [9.0, 9.5, 10.0, 11.0]),
         "rattler_fraction": ("sample", [0.0, 0.1, 0.2, 0.0])},
        coords={"beta": ("sample", [0.0, 0.0, 0.0, 0.5]), "alpha": ("sample", [1.5, 1.5, 1.5, 2.0]),
                "seed": ("sample", [1, 2, 3, 1])})
    out = verdict_fractions(summary)
    first = out.isel(shape=0)
    assert float(first.alpha) == 1.5 and int(first.n_packings) == 3
    assert float(first.fraction_jammed) == pytest.approx(2 / 3)
    assert (float(first.fraction_first), float(first.fraction_second), float(first.fraction_undetermined)) == \
        pytest.approx((1 / 3, 1 / 3, 1 / 3))
    assert float(first.z_backbone) == pytest.approx(9.5) and float(first.z_backbone_err) == pytest.approx(0.5 / 3**0.5)
    assert float(first.rattler_fraction) == pytest.approx(0.1)
    assert np.isnan(float(out.isel(shape=1).z_backbone_err)) and np.isnan(float(first.fraction_refined))
    refined = verdict_fractions(summary.assign(refined=("sample", [1, 0, 0, 1])))
    assert float(refined.isel(shape=0).fraction_refined) == pytest.approx(1 / 3)


@pytest.mark.parametrize("name", ["mm_n80_seed1_slow_p1e12", "self_dual_a1.05_n100_slow_p1e12"])
def test_sparse_path_projects_the_stiffness_like_the_dense_one(name):
    """LS packings at p = 1e12: M&M-shaped oblate spheroids (alpha = 1.9, N = 80, final rate 1e-3;
    one floppy mode) and near-sphere ellipsoids (224 floppy modes). The sparse path's floppy space
    (inertia count, shift-invert eigsh, Rayleigh-Ritz with the near self-stress) gives the dense
    SVD's counts and lambda_min(K_V). Donev's shifted form k A A^T + K with k = 1e3 |K| / |A A^T|
    gave -0.024 against the projected -0.0019 on the M&M packing: its smallest nonzero singular
    value of A^T is 5e-3 of the largest, so k s^2 ~ |K|."""
    packing = _packing(name)
    dense = verify_ellipsoids(packing, delta="gaps", method="dense")
    sparse = verify_ellipsoids(packing, delta="gaps", method="sparse")
    d, s = dense.collective, sparse.collective
    assert (s.n_stresses, s.n_floppy, s.n_constraints, s.n_dof) == (d.n_stresses, d.n_floppy, d.n_constraints, d.n_dof)
    assert d.n_floppy >= 1 and d.n_stresses == 1
    assert s.lambda_min == pytest.approx(d.lambda_min, rel=1e-6)
    assert (sparse.verdict, sparse.order) == (dense.verdict, dense.order)
    assert s.jamming_distance == pytest.approx(d.jamming_distance, rel=1e-3)
    assert sparse.fallbacks["sparse_eigsh_dense"] == 0
