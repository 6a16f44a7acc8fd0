"""``hardpack structure`` (hardpack.structure.cli) and the combined analysis Dataset."""

import argparse

import numpy as np
import pytest
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.lattices import lattice_packing
from hardpack.io import save_packing, write_dataset
from hardpack.structure import cli
from hardpack.structure.analysis import analyse


def run(argv):
    parser = argparse.ArgumentParser()
    cli.register(parser.add_subparsers())
    args = parser.parse_args(argv)
    return args.func(args)


def test_cli_writes_structure_of_a_crystal(tmp_path):
    p = lattice_packing("fcc", 4)
    mask = np.zeros(p.n_particles, bool)
    mask[0] = True
    src, out = tmp_path / "fcc.nc", tmp_path / "fcc_structure.nc"
    save_packing(p, src)
    verdict = tmp_path / "verdict.nc"
    write_dataset(xr.Dataset({"rattler": ("particle", mask.astype(np.int8))},
                             attrs={"hardpack_kind": "jamming"}), verdict)
    assert run(["structure", str(src), "--out", str(out), "--jamming", str(verdict),
                "--kmax", "9", "--rmax", "2"]) == 0
    with xr.open_dataset(out) as ds:
        assert ds.attrs["hardpack_kind"] == "structure"
        assert float(ds.z_contacts) == 12.0
        assert abs(float(ds.Q6) - 0.57452) < 1e-5 and abs(float(ds["T"]) - 1) < 1e-12
        assert float(ds.crystallinity) == 1.0
        n = p.n_particles
        plateau = (ds.gap.values > 1e-12) & (ds.gap.values < 0.4)
        np.testing.assert_allclose(ds.Z_backbone.values[plateau], 2 * (6 * n - 12) / (n - 1))
        bragg = ds.S.values > 1  # FCC: S is N on Bragg shells and 0 elsewhere
        assert np.all(ds.S.values[~bragg] < 1e-16)


def test_cli_stores_the_attributes_it_is_given(tmp_path):
    """The workflow names each structure dataset's ensemble (`--attr ensemble=NAME`); the validation
    and the figures group by it."""
    src, out = tmp_path / "sc.nc", tmp_path / "sc_structure.nc"
    save_packing(lattice_packing("sc", 3), src)
    assert run(["structure", str(src), "--out", str(out), "--no-order", "--attr", "ensemble=mono3d",
                "--attr", "note=x"]) == 0
    with xr.open_dataset(out) as ds:
        assert ds.attrs["ensemble"] == "mono3d" and ds.attrs["note"] == "x"
        assert ds.attrs["source"] == str(src)


def test_cli_refuses_a_verdict_of_another_packing(tmp_path):
    src = tmp_path / "sc.nc"
    save_packing(lattice_packing("sc", 3), src)
    verdict = write_dataset(xr.Dataset({"rattler": ("particle", np.zeros(5, np.int8))},
                                       attrs={"hardpack_kind": "jamming"}), tmp_path / "v.nc")
    with pytest.raises(InvalidInputError, match="no per-particle 'rattler' mask for the 27 particles"):
        run(["structure", str(src), "--out", str(tmp_path / "o.nc"), "--jamming", str(verdict)])


def test_analyse_two_dimensional_packing_has_psi6():
    ds = analyse(lattice_packing("triangular", (8, 9)), k_max=8.0)
    assert abs(float(ds.psi6_global) - 1) < 1e-12 and "Q6" not in ds


def test_cli_reports_a_verdict_without_backbone(tmp_path):
    """Every particle a rattler: no backbone. The output says so (verdict, count) and has no
    backbone quantities, instead of passing off an analysis of all particles as one without
    rattlers (the near-contact exponent alpha is the backbone's when a mask is given)."""
    src = tmp_path / "sc.nc"
    save_packing(lattice_packing("sc", 3), src)
    verdict = write_dataset(xr.Dataset({"rattler": ("particle", np.ones(27, np.int8))},
                                       attrs={"hardpack_kind": "jamming", "verdict": "not jammed"}),
                            tmp_path / "v.nc")
    out = tmp_path / "o.nc"
    assert run(["structure", str(src), "--out", str(out), "--jamming", str(verdict), "--kmax", "7"]) == 0
    with xr.open_dataset(out) as ds:
        assert ds.attrs["rattler_mask"] == str(verdict)
        assert ds.attrs["backbone"].startswith("none") and ds.attrs["n_rattlers"] == 27
        assert ds.attrs["jamming_verdict"] == "not jammed"
        assert "Z_backbone" not in ds and np.isnan(float(ds.alpha))
        assert float(ds.z_contacts) == 6.0  # all-particle quantities stay
