"""Lubachevsky-Stillinger compression: jamming densities against published values, the
free-volume law near jamming, conservation laws at zero growth, stop criteria, outputs, and
refusal of impossible inputs.

Published targets: 3D monodisperse LS packings from a liquid jam
at phi_J = 0.635-0.655 for a wide range of rates (Donev 2006, sec. 1.2 and Fig. 1.3; Skoge et al. 2006: 0.64);
2D equimolar binary disks with diameter ratio 1.4 jam near 0.84 (Donev 2006, sec. 1.3.2.1); 4D monodisperse
near 0.46 (Skoge et al. 2006, Table I). Near jamming p = d / (1 - phi/phi_J) (Donev 2006, Eq. 1.1).
"""

import numpy as np
import pytest

from hardpack.distributions import bidisperse, monodisperse
from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.initial import random_packing
from hardpack.io import dataset_to_packing, load_dataset, load_packing
from hardpack.md import StopCriteria, compress


@pytest.fixture(scope="module")
def mono3d():
    return random_packing(500, 3, monodisperse(0.5), 0.3, seed=11)


@pytest.fixture(scope="module")
def jammed3d(mono3d):
    return compress(mono3d, 0.02, seed=1, stop=StopCriteria(max_pressure=1e10))


def _assert_clean(result, tol=1e-9):
    report = result.packing.overlap_report(tol)
    assert report.n_overlapping == 0, str(report)
    assert result.stats["overlap_check"] == "passed"
    assert np.nanmax(result.timeseries.max_overlap.values) < tol


def test_3d_monodisperse_jams_in_the_published_window(jammed3d):
    s = jammed3d.stats
    assert s["stop_reason"] == "max_pressure" and s["Z"] >= 1e10
    assert 0.63 <= s["phi"] <= 0.66
    # at Z >= 1e10 the estimate phi / (1 - d/Z) differs from phi by ~ phi d / Z < 1e-9
    assert abs(s["phi_J_est"] - s["phi"]) < 1e-8
    _assert_clean(jammed3d)


@pytest.mark.parametrize("d, n, phi0, low, high", [(5, 243, 0.12, 0.28, 0.33), (6, 729, 0.06, 0.18, 0.22)])
def test_high_dimensional_ls_in_small_boxes_jams_near_mrj(d, n, phi0, low, high):
    # Torquato & Jiao's Table II cells (N = 3^d, a box of ~3 diameters): image codes of the
    # neighbour lists reach 4^d - 1 here. phi_J of fast LS: 0.31 (d = 5) and 0.20 (d = 6) (Donev
    # 2006, Table 11.1); at Z = 1e3 phi is a few tenths of a percent below it.
    run = compress(random_packing(n, d, monodisperse(0.5), phi0, seed=1), 0.02, seed=1,
                   stop=StopCriteria(max_pressure=1e3))
    assert run.stats["stop_reason"] == "max_pressure"
    assert low <= run.stats["phi"] <= high
    _assert_clean(run)


def test_free_volume_law_near_jamming(jammed3d):
    """p (1 - phi/phi_J) -> d: median over windows with 1e4 < Z < 1e8 within 10 % of d = 3
    (rattlers and the finite rate make it approach d from either side by a few percent)."""
    ts = jammed3d.timeseries
    phi_j = jammed3d.stats["phi"]  # phi_J - phi_final ~ phi d / Z_final < 1e-9
    sel = (ts.Z > 1e4) & (ts.Z < 1e8)
    assert int(sel.sum()) >= 20
    product = (ts.Z * (1 - ts.phi / phi_j))[sel].values
    assert np.median(product) == pytest.approx(3.0, rel=0.1)


def test_2d_binary_disks_jam_near_084():
    packing = random_packing(500, 2, bidisperse(1.4, 0.5), 0.5, seed=5)
    result = compress(packing, 0.02, seed=2, stop=StopCriteria(max_pressure=1e10))
    assert result.stats["Z"] >= 1e10
    assert result.stats["phi"] == pytest.approx(0.84, abs=0.01)
    _assert_clean(result)


@pytest.mark.slow
def test_4d_monodisperse_jams_near_046():
    packing = random_packing(1000, 4, monodisperse(0.5), 0.2, seed=4)
    result = compress(packing, 0.02, seed=3, stop=StopCriteria(max_pressure=1e10))
    assert result.stats["Z"] >= 1e10
    assert result.stats["phi"] == pytest.approx(0.46, abs=0.015)
    _assert_clean(result)


def test_zero_growth_conserves_energy_and_momentum(mono3d):
    """Gamma = 0 (no rescaling): KE and momentum stay at their start values (kT = 1, P = 0) to
    round-off at every one of the windows over 1e5 collisions."""
    result = compress(mono3d, 0.0, seed=7, stop=StopCriteria(max_pressure=None, max_collisions=100_000))
    assert result.stats["collisions"] == 100_000
    kt = result.timeseries.kT.values
    assert np.abs(kt - 1.0).max() < 1e-12
    v = result.velocities
    assert 0.5 * np.sum(v * v) / (1.5 * len(v)) == pytest.approx(1.0, abs=1e-12)
    assert np.abs(v.sum(axis=0)).max() < 1e-11
    _assert_clean(result)


def test_target_phi_is_hit_exactly(mono3d):
    result = compress(mono3d, 0.05, seed=1, stop=StopCriteria(max_pressure=None, target_phi=0.5))
    assert result.stats["stop_reason"] == "target_phi"
    assert result.packing.phi == pytest.approx(0.5, rel=1e-12)
    # the time series records where it started (its first window's lower end)
    assert result.timeseries.attrs["phi_start"] == mono3d.phi
    assert result.timeseries["phi"].values[-1] == pytest.approx(0.5, rel=1e-12)
    # sizes stay proportional to the start sizes (monodisperse here: all equal)
    assert np.ptp(result.packing.radii) < 1e-12


def test_shrinking_run_reaches_lower_phi(jammed3d):
    result = compress(jammed3d.packing, -0.05, seed=2,
                      stop=StopCriteria(max_pressure=None, target_phi=0.5))
    assert result.stats["stop_reason"] == "target_phi"
    assert result.packing.phi == pytest.approx(0.5, rel=1e-12)
    _assert_clean(result)


def test_max_collisions_is_exact_and_progress_is_reported(mono3d):
    seen = []
    result = compress(mono3d, 0.02, seed=1, stop=StopCriteria(max_collisions=12_345),
                      progress=seen.append)
    assert result.stats["stop_reason"] == "max_collisions"
    assert result.stats["collisions"] == 12_345
    assert [r["collisions"] for r in seen] == list(result.timeseries.collisions.values)


def test_outputs_are_written_with_run_attributes(tmp_path, jammed3d):
    jammed3d.save(tmp_path / "p.nc", tmp_path / "ts.nc")
    back = load_packing(tmp_path / "p.nc")
    np.testing.assert_array_equal(back.radii, jammed3d.packing.radii)
    attrs = load_dataset(tmp_path / "p.nc").attrs
    for key in ("growth_rate", "seed", "stop_reason", "Z", "phi", "phi_J_est", "collisions",
                "wall_time", "overlap_check"):
        assert key in attrs
    ts = load_dataset(tmp_path / "ts.nc")
    assert ts.sizes["window"] == jammed3d.stats["windows"]
    for name in ("phi", "Z", "phi_J_est", "collisions", "time", "kT"):
        assert name in ts


def test_to_dataset_is_the_packing_with_the_run_stats(jammed3d):
    ds = jammed3d.to_dataset()
    assert ds.attrs["hardpack_kind"] == "packing"
    assert ds.attrs["stop_reason"] == jammed3d.stats["stop_reason"]
    back = dataset_to_packing(ds)
    np.testing.assert_array_equal(back.positions, jammed3d.packing.positions)
    np.testing.assert_array_equal(back.radii, jammed3d.packing.radii)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"growth_rate": float("nan")}, "finite"),
        ({"growth_rate": -0.1}, "target_phi below"),
        ({"growth_rate": 0.0}, "never raises"),
        ({"growth_rate": 0.1, "stop": StopCriteria(target_phi=0.2)}, "not above"),
        ({"growth_rate": 0.1, "stop": StopCriteria(max_pressure=None)}, "no stop criterion"),
        ({"growth_rate": 0.1, "seed": -1}, "seed"),
    ],
)
def test_refuses_impossible_requests(mono3d, kwargs, message):
    args = {"growth_rate": 0.1, "seed": 0} | kwargs
    with pytest.raises(InvalidInputError, match=message):
        compress(mono3d, **args)


def test_refuses_sheared_overlapping_and_cramped_packings():
    sheared = Packing([[0.2, 0.2], [0.7, 0.7]], [0.1, 0.1], [[1.0, 0.3], [0.0, 1.0]])
    with pytest.raises(InvalidInputError, match="sheared"):
        compress(sheared, 0.1, 0)
    overlapping = Packing([[0.2, 0.2], [0.3, 0.2]], [0.1, 0.1], np.eye(2), allow_overlap=True)
    with pytest.raises(InvalidInputError, match="overlapping"):
        compress(overlapping, 0.1, 0)
    cramped = Packing([[0.25, 0.5, 0.5], [0.75, 0.5, 0.5]], [0.2499, 0.2499], np.eye(3))
    with pytest.raises(InvalidInputError, match="box is too small"):
        compress(cramped, 0.1, 0)
