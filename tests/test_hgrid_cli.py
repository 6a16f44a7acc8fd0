"""`hardpack hgrid-cost` writes the Fig. 2.15 curves as a netCDF dataset."""

import argparse

import pytest

from hardpack.hgrid.cli import register
from hardpack.io import load_dataset


def test_figure_2_15_curves(tmp_path):
    out = tmp_path / "cost.nc"
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    args = parser.parse_args(
        [
            "hgrid-cost",
            "--alpha",
            "-3",
            "--omega",
            "100",
            "--rules",
            "exponential",
            "constant-m",
            "--max-levels",
            "14",
            "--out",
            str(out),
        ]
    )
    assert args.func(args) == 0
    ds = load_dataset(out, kind="hgrid_cost")
    assert int(ds["cost"].sel(rule="constant-m").idxmin()) == 12
    assert float(ds["cost"].sel(rule="exponential").min()) == pytest.approx(12.13, abs=0.005)
    assert ds.attrs["linked_cell_cost"] == pytest.approx(91146, abs=0.5)
