"""`hardpack poly-equivalents` writes Tables 3.1 / 3.3 as a netCDF dataset."""

import argparse

import numpy as np
import pytest

from hardpack.eos.cli import register
from hardpack.errors import InvalidInputError
from hardpack.io import load_dataset


def run(argv):
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    args = parser.parse_args(argv)
    return args.func(args)


def test_uniform_volume_table(tmp_path):
    out = tmp_path / "uv.nc"
    assert run(["poly-equivalents", "--kind", "uniform_volume", "--values", "2", "10", "--out", str(out)]) == 0
    ds = load_dataset(out, kind="eos_equivalents")
    # Table 3.1 (R_bi, n1_bi) and Table 3.3 (n1, delta2) at omega = 2 and 10
    assert ds["bi_R"].values == pytest.approx([1.49, 3.90], abs=0.005)
    assert ds["bi_n1"].values == pytest.approx([0.327, 0.080], abs=5e-4)
    assert ds["tri_n1"].values[0] == pytest.approx(0.1427, abs=5e-5)
    assert ds["tri_n1"].values[1] == pytest.approx(0.01661, abs=5e-6)
    assert ds["tri_delta2"].values == pytest.approx([0.4337, 0.3419], abs=5e-5)
    assert np.all(np.diff(ds["tri_radii"].values, axis=1) < 0)  # a1 >= a2 >= a3


def test_bad_family_arguments(tmp_path):
    with pytest.raises(SystemExit):  # argparse refuses an unknown family
        run(["poly-equivalents", "--kind", "gaussian", "--values", "1", "--out", str(tmp_path / "x.nc")])
    with pytest.raises(InvalidInputError, match="alpha"):
        run(["poly-equivalents", "--kind", "power_law", "--values", "3", "--out", str(tmp_path / "x.nc")])
