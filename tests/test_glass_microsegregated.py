"""Micro-segregated binary disk packings (hardpack.glass.microsegregated; Donev 2006, sec. 13.5).

- growing the B disks of a labelled 8 x 8 triangular crystal at reduced pressure p = 100 ends at
  the diameter ratio 1.4 exactly (to round-off), leaves the A radii untouched, and holds the
  pressure: the mean relative pressure error is a lag proportional to the growth rate (halving
  the rate halves it within three standard errors), so the quasi-static limit of the text's
  gamma = 1e-5 holds p to ~1e-3; the start of the growth has phi_J_est ~ 0.91 (Fig. 13.14:
  "decreases from ~0.91");
- the whole protocol jams (reduced pressure reached, no overlap) and carries phi_J and the
  labels' s_c in the packing's attributes, through the CLI too;
- bad input is refused.
"""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.glass.microsegregated import PHI_MAX, grow_species, microsegregated_packing, start_phi
from hardpack.glass.segregated import label_ensemble, label_study, labelled_crystal


@pytest.fixture(scope="module")
def crystal():
    labels, _, _ = label_ensemble((8, 8), 2.0, 0.5, 2 / 3, 1, 1)
    return labelled_crystal(labels[0], start_phi(100.0))


def _mean_error(ts, blocks=10):
    """Time-weighted mean of Z / p - 1 after the first tenth, and its block standard error."""
    e = ts.pressure_error.values
    w = np.diff(np.concatenate([[0.0], ts.time.values]))
    h = len(e) // 10
    means = [np.average(b, weights=c) for b, c in zip(np.array_split(e[h:], blocks), np.array_split(w[h:], blocks))]
    return np.mean(means), np.std(means, ddof=1) / np.sqrt(blocks)


def test_start_phi_is_the_free_volume_density():
    assert start_phi(100.0) == pytest.approx(0.98 * np.pi / np.sqrt(12))
    with pytest.raises(InvalidInputError, match="pressure"):
        start_phi(1.5)


def test_b_growth_holds_the_pressure_with_a_lag_proportional_to_the_rate(crystal):
    b = crystal.species == 1
    runs = {}
    for gamma in (1e-3, 5e-4):
        grown, ts, stats = grow_species(crystal, 1, 1.4, 100.0, gamma, 3)
        assert grown.radii[b] / grown.radii[~b][0] == pytest.approx(1.4, rel=1e-12)
        np.testing.assert_array_equal(grown.radii[~b], crystal.radii[~b])
        assert stats["growth_overlap_check"] == "passed"
        assert ts.phi_J_est.values[0] == pytest.approx(PHI_MAX, abs=0.01)
        runs[gamma] = _mean_error(ts)
    (e1, s1), (e2, s2) = runs[1e-3], runs[5e-4]
    assert 0 < e2 < e1 < 0.15, runs
    assert abs(e1 - 2 * e2) < 3 * np.hypot(s1, 2 * s2), runs


def test_protocol_jams_and_carries_phi_j_and_s_c(tmp_path):
    from hardpack.cli import main
    from hardpack.io import load_dataset, write_dataset

    labels = label_study((8, 8), 2.0, 0.5, 2 / 3, 1, count=4, window=(3, 3))
    path = tmp_path / "labels.nc"
    write_dataset(labels, path, seed=1)
    out = tmp_path / "jammed.nc"
    growth = tmp_path / "growth.nc"
    assert main(["glass-microsegregated", "--labels", str(path), "--growth-rate", "1e-2", "--compress-rate", "1e-2",
                 "--max-pressure", "1e7", "--seed", "2", "--out", str(out), "--growth-timeseries", str(growth)]) == 0
    ds = load_dataset(out)
    assert ds.attrs["stop_reason"] == "max_pressure" and ds.attrs["overlap_check"] == "passed"
    assert ds.attrs["s_c"] == float(labels["entropy_per_site"].values[2, 2]) and ds.attrs["s_c_window"] == "3x3"
    assert ds.attrs["growth_ratio"] == pytest.approx(1.4, rel=1e-12)
    assert 0.8 < ds.attrs["phi_J"] < PHI_MAX
    assert ds.attrs["phi_J"] == pytest.approx(ds.attrs["phi_J_est"], rel=1e-6)  # jammed at Z = 1e7
    assert load_dataset(growth)["size_ratio"].values[-1] == pytest.approx(1.4, rel=1e-12)


@pytest.mark.parametrize("kwargs, match", [
    ({"ratio": 1.0}, "ratio"), ({"pressure": 2.0}, "pressure"), ({"growth_rate": 0.0}, "growth_rate"),
    ({"species": 7}, "species"),
])
def test_bad_growth_input_is_refused(crystal, kwargs, match):
    args = {"species": 1, "ratio": 1.4, "pressure": 100.0, "growth_rate": 1e-3, "seed": 0} | kwargs
    with pytest.raises(InvalidInputError, match=match):
        grow_species(crystal, **args)


def test_bad_protocol_input_is_refused():
    labels = label_study((8, 8), 2.0, 0.5, 2 / 3, 1, count=1, window=(2, 2))
    with pytest.raises(InvalidInputError, match="realisation"):
        microsegregated_packing(labels, 1)
    with pytest.raises(InvalidInputError, match="compress_rate"):
        microsegregated_packing(labels, 0, compress_rate=-1.0)
    with pytest.raises(InvalidInputError, match="glass_labels"):
        microsegregated_packing(labels.assign_attrs(hardpack_kind="packing"), 0)


def _fake_packing(ensemble, R, nu, s_c, phi_j, n=1024):
    import xarray as xr

    return xr.Dataset(attrs={"ensemble": ensemble, "R": R, "nu": nu, "s_c": s_c, "s_33": s_c, "s_mix": 0.6365,
                             "phi_J": phi_j, "N": n, "s_c_window": "4x4", "growth_phi_J_est_start": 0.907,
                             "growth_pressure_error_mean": 0.001})


def _fake_summary(n=1024, clustered_gain=0.004, spread=0.001):
    from hardpack.glass.microsegregated import summary_dataset

    packings = []
    ensembles = [("random", 0.01, 0.5, 0.63), ("R1_nu0.1", 1, 0.1, 0.60), ("R1_nu0.5", 1, 0.5, 0.55),
                 ("R3_nu0.3", 3, 0.3, 0.45), ("R5_nu0.1", 5, 0.1, 0.40), ("R5_nu0.5", 5, 0.5, 0.30)]
    for k, (name, R, nu, s) in enumerate(ensembles):
        for dphi in (-spread, spread):
            packings.append(_fake_packing(name, R, nu, s, 0.846 + clustered_gain * k / 5 + dphi, n))
    return summary_dataset(packings)


def test_summary_groups_the_ensembles():
    ds = _fake_summary()
    assert list(ds.ensemble.values) == ["R1_nu0.1", "R1_nu0.5", "R3_nu0.3", "R5_nu0.1", "R5_nu0.5", "random"]
    row = ds.sel(ensemble="R5_nu0.5")
    assert float(row.phi_J) == pytest.approx(0.850) and int(row.n_packings) == 2
    assert float(row.phi_J_err) == pytest.approx(0.001)  # sd sqrt(2) * 0.001 / sqrt(2)
    with pytest.raises(InvalidInputError, match="mixes"):
        from hardpack.glass.microsegregated import summary_dataset

        summary_dataset([_fake_packing("a", 1, 0.1, 0.5, 0.85), _fake_packing("a", 2, 0.1, 0.5, 0.85)])


def test_rows_judge_the_text_claims():
    from hardpack.validation.glass import microsegregated_rows

    rows = {r.target: r for r in microsegregated_rows(_fake_summary())}
    assert rows["donev-13.5-phij-random"].status == "pass"
    assert rows["donev-13.5-phij-est-start"].status == "pass"
    assert rows["donev-13.5-clustered-denser"].status == "pass"
    assert rows["donev-13.5-sc-phij-anticorrelated"].status == "pass"
    # no gain from clustering: both claims fail; a small system: every row n/a
    flat = {r.target: r for r in microsegregated_rows(_fake_summary(clustered_gain=0.0))}
    assert flat["donev-13.5-clustered-denser"].status == "fail"
    assert flat["donev-13.5-sc-phij-anticorrelated"].status == "fail"
    small = microsegregated_rows(_fake_summary(n=64))
    assert {r.status for r in small} == {"n/a"}
    few = microsegregated_rows(_fake_summary().isel(ensemble=[0, 4, 5]))
    assert [r.status for r in few if r.target == "donev-13.5-sc-phij-anticorrelated"] == ["n/a"]


def test_figure_draws(tmp_path):
    from hardpack.plots.glass import plot_microsegregated
    from hardpack.plots.style import save

    save(plot_microsegregated(_fake_summary()), tmp_path / "f.png")
    assert (tmp_path / "f.png").stat().st_size > 0


# --- Figs. 13.16-13.17: the exponential fit of s_c(phi_J) and the (R, nu) maps -----------------

def _exponential(phi, s_ref=0.6, decay=150.0, phi_ref=0.846):
    return s_ref * np.exp(-decay * (np.asarray(phi) - phi_ref))


def test_exponential_fit_is_exact_on_exact_data_at_any_reference_density():
    from hardpack.glass.microsegregated import fit_sc_exponential

    phi = np.linspace(0.846, 0.862, 7)
    fit = fit_sc_exponential(phi, _exponential(phi))
    assert fit.s_ref == pytest.approx(0.6, rel=1e-9) and fit.decay == pytest.approx(150.0, rel=1e-9)
    assert fit.s_ref_err < 1e-9 and fit.decay_err < 1e-6 and fit.n_points == 7
    np.testing.assert_allclose(fit(phi), _exponential(phi), rtol=1e-9)
    # quoting s_ref at another density moves s_ref along the curve and leaves the decay
    moved = fit_sc_exponential(phi, _exponential(phi), phi_ref=0.85)
    assert moved.s_ref == pytest.approx(_exponential(0.85), rel=1e-9) and moved.decay == pytest.approx(150.0)


def test_exponential_fit_recovers_known_parameters_with_calibrated_errors():
    """Noisy synthetic data (n = 10, sd 0.01 in s_c): over 400 replicates the estimates centre on
    the true (s_ref, decay) and the reported standard errors match the replicates' scatter."""
    from hardpack.glass.microsegregated import fit_sc_exponential

    rng = np.random.default_rng(11)
    phi = np.linspace(0.846, 0.862, 10)
    fits = [fit_sc_exponential(phi, _exponential(phi) + rng.normal(0.0, 0.01, phi.size)) for _ in range(400)]
    for name, true in (("s_ref", 0.6), ("decay", 150.0)):
        values = np.array([getattr(f, name) for f in fits])
        errors = np.array([getattr(f, name + "_err") for f in fits])
        sd = values.std(ddof=1)
        assert abs(values.mean() - true) < 3 * sd / np.sqrt(values.size), name
        assert errors.mean() / sd == pytest.approx(1.0, abs=0.15), name  # scatter of sd: 3.5 %
        inside = np.mean(np.abs(values - true) < 2 * errors)
        assert 0.85 < inside < 0.98, name  # Student t with 8 dof: 0.92


@pytest.mark.parametrize("phi, s, match", [
    ([0.85, 0.86], [0.5, 0.4], "at least 3 points"),
    ([0.85, np.nan, 0.87], [0.5, 0.4, 0.3], "finite"),
    ([0.85, 0.86, 0.87], [0.5, np.inf, 0.3], "finite"),
    ([0.85, 0.86, 0.87], [0.5, 0.4], "one value per ensemble"),
    ([0.85, 0.86, 0.87], [0.5, 0.0, 0.3], "positive"),
    ([0.85, 0.85, 0.85], [0.5, 0.4, 0.3], "undetermined"),
])
def test_exponential_fit_refuses_bad_input(phi, s, match):
    from hardpack.glass.microsegregated import fit_sc_exponential

    with pytest.raises(InvalidInputError, match=match):
        fit_sc_exponential(phi, s)


def test_summary_carries_the_fit_or_says_why_not(tmp_path):
    from hardpack.glass.microsegregated import ExponentialFit, fit_sc_exponential, summary_dataset
    from hardpack.io import load_dataset, write_dataset

    ds = _fake_summary()
    assert ds.attrs["sc_fit_status"] == "fitted" and ds.attrs["sc_fit_points"] == 6
    direct = fit_sc_exponential(ds["phi_J"].values, ds["s_c"].values)
    write_dataset(ds, tmp_path / "s.nc", seed=1)
    assert ExponentialFit.from_attrs(load_dataset(tmp_path / "s.nc").attrs) == direct
    two = summary_dataset([_fake_packing("random", 0.01, 0.5, 0.63, 0.846), _fake_packing("R1", 1, 0.1, 0.6, 0.847)])
    assert two.attrs["sc_fit_status"].startswith("not fitted") and "at least 3 points" in two.attrs["sc_fit_status"]
    assert np.isnan(two.attrs["sc_fit_s_ref"]) and ExponentialFit.from_attrs(two.attrs) is None


def test_grid_maps_put_each_ensemble_in_its_cell_and_leave_missing_cells_missing():
    from hardpack.glass.microsegregated import grid_maps

    ds = _fake_summary()  # R1_nu0.1, R1_nu0.5, R3_nu0.3, R5_nu0.1, R5_nu0.5 and random
    maps = grid_maps(ds, [5, 3, 1], [0.1, 0.3, 0.5])
    assert maps["R"].values.tolist() == [5, 3, 1] and maps["nu"].values.tolist() == [0.1, 0.3, 0.5]
    cell = maps.sel(R=3, nu=0.3)
    assert str(cell["ensemble"].values) == "R3_nu0.3"
    assert float(cell["phi_J"]) == float(ds.sel(ensemble="R3_nu0.3")["phi_J"])
    assert float(cell["s_c"]) == float(ds.sel(ensemble="R3_nu0.3")["s_c"])
    missing = maps.sel(R=1, nu=0.3)
    assert np.isnan(float(missing["phi_J"])) and np.isnan(float(missing["s_c"])) and int(missing["n_packings"]) == 0
    assert maps.attrs["missing_cells"] == 4 and maps.attrs["off_grid"] == "random"
    assert int(np.isfinite(maps["phi_J"].values).sum()) == 5


@pytest.mark.parametrize("r_values, nu_values, match", [
    ([], [0.1], "non-empty"), ([1, np.nan], [0.1], "finite"), ([1, 1], [0.1], "repeat"),
])
def test_grid_maps_refuse_a_bad_grid(r_values, nu_values, match):
    from hardpack.glass.microsegregated import grid_maps

    with pytest.raises(InvalidInputError, match=match):
        grid_maps(_fake_summary(), r_values, nu_values)


def test_grid_maps_refuse_two_ensembles_in_one_cell_and_other_datasets():
    from hardpack.glass.microsegregated import grid_maps, summary_dataset

    twins = summary_dataset([_fake_packing(name, 1, 0.1, 0.5, 0.85) for name in ("a", "b", "c")])
    with pytest.raises(InvalidInputError, match="same"):
        grid_maps(twins, [1], [0.1])
    with pytest.raises(InvalidInputError, match="microsegregated_summary"):
        grid_maps(_fake_summary().assign_attrs(hardpack_kind="packing"), [1], [0.1])


def test_figures_show_the_fit_and_the_missing_cells(tmp_path):
    from hardpack.glass.microsegregated import grid_maps, summary_dataset
    from hardpack.plots.glass import plot_microsegregated, plot_microsegregated_maps
    from hardpack.plots.style import save

    fig = plot_microsegregated(_fake_summary())
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any("fit" in t and r"s_{\rm ref}" in t for t in labels), labels
    save(fig, tmp_path / "fit.png")
    two = summary_dataset([_fake_packing("random", 0.01, 0.5, 0.63, 0.846), _fake_packing("R1", 1, 0.1, 0.6, 0.847)])
    fig = plot_microsegregated(two)
    assert any("not fitted" in t.get_text() for t in fig.legends[0].get_texts())
    save(fig, tmp_path / "nofit.png")

    fig = plot_microsegregated_maps(grid_maps(_fake_summary(), [1, 3, 5], [0.1, 0.3, 0.5]))
    panels = [ax for ax in fig.axes if ax.get_xlabel().startswith(r"$\nu$")]
    assert len(panels) == 2
    for ax in panels:
        mesh = ax.collections[0].get_array()
        assert int(np.ma.count_masked(mesh)) == 4  # missing, not drawn as a value
        assert [t.get_text() for t in ax.texts].count("missing") == 4
        assert [t.get_text() for t in ax.get_xticklabels()] == ["0.1", "0.3", "0.5"]
    colourbar_labels = {ax.get_ylabel() for ax in fig.axes if ax not in panels}
    assert any(r"\phi_J" in s for s in colourbar_labels) and any("s_c" in s for s in colourbar_labels)
    save(fig, tmp_path / "maps.png")
    assert all((tmp_path / f).stat().st_size > 0 for f in ("fit.png", "nofit.png", "maps.png"))
