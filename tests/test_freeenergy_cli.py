"""``hardpack bcmd`` subcommand, driven through its own argparse registration."""

import argparse

import numpy as np
import pytest

from hardpack.cli import main
from hardpack.freeenergy import cli
from hardpack.geometry.lattices import lattice_packing
from hardpack.io import load_dataset, save_packing


def parse(argv):
    parser = argparse.ArgumentParser()
    cli.register(parser.add_subparsers())
    return parser.parse_args(argv)


def test_bcmd_cli_disjoint(tmp_path):
    # half-size spheres at phi/8: disjoint cells throughout, Delta f = d ln(dmu_max/dmu_min)
    src = tmp_path / "fcc.nc"
    save_packing(lattice_packing("fcc", (2, 2, 2)), src)
    out = tmp_path / "res.nc"
    phi = 0.74048048969 / 8
    args = parse(
        [
            "bcmd",
            str(src),
            "--out",
            str(out),
            "--phi",
            str(phi),
            "--dmu-max",
            "0.4",
            "--dmu-min",
            "0.1",
            "--gamma0",
            "2e-3",
            "--theta",
            "0",
            "--seed",
            "2",
        ]
    )
    assert args.func(args) == 0
    ds = load_dataset(out)
    assert ds.attrs["delta_f"] == pytest.approx(3 * np.log(4.0), abs=2e-3)
    assert ds.attrs["phi"] == pytest.approx(phi, rel=1e-9)


def test_bcmd_cli_refuses(tmp_path, capsys):
    src = tmp_path / "fcc.nc"
    save_packing(lattice_packing("fcc", (2, 2, 2)), src)
    status = main(["bcmd", str(src), "--out", str(tmp_path / "r.nc"), "--dmu-max", "0.1"])
    assert status == 2  # touching spheres: cells never disjoint
    assert "hardpack bcmd: error: the cells are never disjoint" in capsys.readouterr().err


def test_bcmd_simplex_cli_not_isostatic(tmp_path, capsys):
    # an FCC crystal is hyperstatic (M = 6N contacts > 3(N-1) + 1): the summary says so, with
    # no BCMD run and NaN values, instead of failing the pipeline
    import xarray as xr

    p = lattice_packing("fcc", (2, 2, 2))
    src, verdict, out = tmp_path / "fcc.nc", tmp_path / "verdict.nc", tmp_path / "res.nc"
    save_packing(p, src)
    xr.Dataset(
        {"rattler": ("particle", np.zeros(p.n_particles, np.int8))},
        attrs={"hardpack_kind": "jamming", "delta": 1e-6},
    ).to_netcdf(verdict)
    args = parse(["bcmd-simplex", str(src), "--jamming", str(verdict), "--out", str(out)])
    assert args.func(args) == 0
    a = load_dataset(out).attrs
    assert a["isostatic"] == 0
    assert a["isostaticity_gap"] == 6 * 32 - (3 * 31 + 1)
    assert np.isnan(a["bcmd"]) and a["n_events"] == 0


def test_bcmd_ladder_cli(tmp_path):
    out = tmp_path / "ladder.nc"
    args = parse(["bcmd-ladder", "--out", str(out)])
    assert args.func(args) == 0
    ds = load_dataset(out)
    # every cheap check's deviation from its exact value within two of its standard errors (the
    # rungs are tested in detail elsewhere; the simplex formula is an identity: round-off only)
    checked = ds.sel(check=[c for c in ds.check.values if c != "bcmd-simplex-formula"])
    assert np.all(np.abs(checked["value"]) <= 2 * checked["error"])
    assert float(ds["value"].sel(check="bcmd-simplex-formula")) < 1e-9


def test_bcmd_ellipse_cli_exact_only(tmp_path, capsys):
    # the alpha = 2 lattice packing of test_freeenergy_ellipses: four particles frozen entirely,
    # 96 free (Donev 2006, Fig. 6.5), exact simplex only
    from pathlib import Path

    src = Path(__file__).parent / "data" / "ellipses_a2_lattice_n100_p1e8.nc"
    out = tmp_path / "ell.nc"
    args = parse(["bcmd-ellipse", str(src), "--out", str(out), "--exact-only"])
    assert args.func(args) == 0
    ds = load_dataset(out)
    assert ds.attrs["n_eff"] == 96 and ds.attrs["isostaticity_gap"] == 0
    assert ds.attrs["freeze"] == "full" and ds.attrs["n_fixed_translation"] == 4
    assert ds.attrs["f_c_j"] == pytest.approx(2.2694, abs=1e-4)
    assert "exact: f_J - f_c^J" in capsys.readouterr().out


def test_bcmd_ellipse_ladder_cli(tmp_path):
    out = tmp_path / "ladder.nc"
    args = parse(["bcmd-ellipse-ladder", "--out", str(out)])
    assert args.func(args) == 0
    assert np.all(np.abs(load_dataset(out)["rel_dev"].values) < 1e-3)
