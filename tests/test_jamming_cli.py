"""``hardpack verify`` subcommand (hardpack.jamming.cli)."""

from __future__ import annotations

import pytest

from hardpack.cli import main
from hardpack.geometry.lattices import lattice_packing
from hardpack.io import load_dataset, save_packing


def _main(argv) -> int:
    """The whole command line (its one error path included)."""
    return main(argv)


def test_verify_writes_verdict(tmp_path, capsys):
    src, out = tmp_path / "fcc.nc", tmp_path / "verdict.nc"
    save_packing(lattice_packing("fcc", 2), src, attrs={"reduced_pressure": 1e12})
    assert _main(["verify", str(src), "--out", str(out), "--delta", "1e-6", "--seed", "3"]) == 0
    printed = capsys.readouterr().out
    assert "verdict: strictly jammed" in printed and "Z=12.0000" in printed
    ds = load_dataset(out, kind="jamming")
    assert ds.attrs["strict"] == 1 and ds.attrs["seed"] == 3 and ds.attrs["md_pressure"] == 1e12
    assert ds.attrs["source"] == str(src) and "git_commit" in ds.attrs


def test_verify_refuses_bad_delta(tmp_path, capsys):
    src = tmp_path / "sq.nc"
    save_packing(lattice_packing("square", 2), src)
    code = _main(["verify", str(src), "--out", str(tmp_path / "v.nc"), "--delta", "-0.1"])
    assert code == 2
    err = capsys.readouterr().err
    assert "delta" in err and "0 < delta < 1" in err
    assert not (tmp_path / "v.nc").exists()


def test_verify_missing_file(tmp_path, capsys):
    assert _main(["verify", str(tmp_path / "nope.nc"), "--out", str(tmp_path / "v.nc")]) == 2
    assert "no such file" in capsys.readouterr().err


@pytest.mark.parametrize("method", ["ideal", "sequential"])
def test_verify_methods(tmp_path, method):
    src = tmp_path / "sq.nc"
    save_packing(lattice_packing("square", (2, 1)), src)
    assert _main(["verify", str(src), "--out", str(tmp_path / "v.nc"), "--method", method,
                  "--tests", "collective", "--delta", "0.01"]) == 0
    ds = load_dataset(tmp_path / "v.nc", kind="jamming")
    assert ds.attrs["method"] == method and ds.attrs["collective"] == 0 and ds.attrs["strict"] == -1
