"""netCDF store: bit-exact round trips, provenance, atomic writes, clear errors, ensembles."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import xarray as xr

from hardpack.distributions import uniform_size
from hardpack.errors import StoreError
from hardpack.geometry import lattice_packing
from hardpack.initial import random_packing
from hardpack.io import combine_ensemble, load_dataset, load_packing, save_packing, write_dataset


def test_round_trip_is_bit_exact(tmp_path):
    p = random_packing(300, 3, uniform_size(3), 0.25, seed=5)
    path = save_packing(p, tmp_path / "p.nc", attrs={"seed": 5, "distribution": "uniform_size"})
    q = load_packing(path)
    assert np.array_equal(p.positions, q.positions)
    assert np.array_equal(p.radii, q.radii)
    assert np.array_equal(p.lattice, q.lattice)
    assert q.phi == p.phi


def test_species_and_sheared_lattice_round_trip(tmp_path):
    p = lattice_packing("hcp", 2)
    p = p.replace(species=np.arange(p.n_particles) % 2)
    q = load_packing(save_packing(p, tmp_path / "h.nc"))
    assert np.array_equal(q.species, p.species)
    assert np.array_equal(q.lattice, p.lattice) and not q.is_orthorhombic


def test_provenance_attributes(tmp_path):
    cfg = {"ensemble": "mono3d", "N": 32, "nested": {"a": [1, 2]}}
    path = save_packing(lattice_packing("fcc", 2), tmp_path / "f.nc", config=cfg, seed=11,
                        attrs={"growth_rate": 0.01, "converged": True})
    attrs = load_dataset(path).attrs
    for key in ("hardpack_version", "git_commit", "created", "numpy_version", "numba_version",
                "xarray_version", "scipy_version", "netCDF4_version", "python_version"):
        assert key in attrs and attrs[key]
    assert attrs["seed"] == 11
    assert '"nested": {"a": [1, 2]}' in attrs["config"]
    assert attrs["growth_rate"] == 0.01 and attrs["converged"] == 1
    assert attrs["N"] == 32 and attrs["d"] == 3 and attrs["hardpack_kind"] == "packing"


def test_interrupted_write_leaves_old_file_intact(tmp_path):
    """A writer killed in the middle of to_netcdf must not damage the existing file."""
    path = tmp_path / "p.nc"
    old = lattice_packing("sc", 2)
    save_packing(old, path)
    before = path.read_bytes()
    script = textwrap.dedent(f"""
        import os, signal
        import xarray as xr
        from hardpack.io import save_packing
        from hardpack.geometry import lattice_packing
        real = xr.Dataset.to_netcdf
        def dying(self, target, *a, **k):
            real(self, target, *a, **k)          # the temp file is fully written...
            os.kill(os.getpid(), signal.SIGKILL)  # ...and the process dies before the rename
        xr.Dataset.to_netcdf = dying
        save_packing(lattice_packing("fcc", 3), {str(path)!r})
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True)
    assert proc.returncode == -9
    assert path.read_bytes() == before
    assert np.array_equal(load_packing(path).positions, old.positions)


def test_failed_write_removes_temp_file_and_keeps_old(tmp_path, monkeypatch):
    path = tmp_path / "p.nc"
    save_packing(lattice_packing("sc", 2), path)
    before = path.read_bytes()

    def boom(self, target, *a, **k):
        with open(target, "wb") as fh:
            fh.write(b"partial")
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", boom)
    with pytest.raises(OSError, match="disk full"):
        save_packing(lattice_packing("fcc", 3), path)
    assert path.read_bytes() == before
    assert os.listdir(tmp_path) == ["p.nc"]


def test_load_errors_name_the_file(tmp_path):
    with pytest.raises(StoreError, match="missing.nc: no such file"):
        load_packing(tmp_path / "missing.nc")
    bad = tmp_path / "garbage.nc"
    bad.write_bytes(b"this is not netcdf")
    with pytest.raises(StoreError, match="garbage.nc cannot be read as netCDF"):
        load_packing(bad)
    other = write_dataset(xr.Dataset({"x": ("a", [1.0])}, attrs={"hardpack_kind": "timeseries"}), tmp_path / "ts.nc")
    with pytest.raises(StoreError, match="ts.nc holds hardpack_kind='timeseries', expected 'packing'"):
        load_packing(other)


def test_load_refuses_a_corrupted_packing(tmp_path):
    path = save_packing(lattice_packing("sc", 2), tmp_path / "p.nc")
    ds = load_dataset(path)
    ds["radius"][:] = 0.9  # now the spheres overlap
    write_dataset(ds, tmp_path / "bad.nc")
    with pytest.raises(StoreError, match="bad.nc holds an invalid packing: particles overlap"):
        load_packing(tmp_path / "bad.nc")
    ds = load_dataset(path).drop_vars("lattice")
    write_dataset(ds, tmp_path / "nolattice.nc")
    with pytest.raises(StoreError, match=r"nolattice.nc is not a hardpack packing: variable\(s\) \['lattice'\]"):
        load_packing(tmp_path / "nolattice.nc")


def test_combine_ensemble_indexes_by_protocol_parameters(tmp_path):
    paths = []
    for seed in (1, 2, 3):
        p = random_packing(50, 2, uniform_size(2), 0.2, seed=seed)
        paths.append(save_packing(p, tmp_path / f"s{seed}.nc",
                                  attrs={"seed": seed, "distribution": "uniform_size", "growth_rate": 0.1}))
    ds = combine_ensemble(paths, index=("seed", "distribution", "growth_rate"))
    assert list(ds["seed"].values) == [1, 2, 3]
    assert ds.sizes["sample"] == 3 and ds["position"].shape == (3, 50, 2)
    assert np.allclose(ds["phi"], 0.2)
    assert ds.set_index(sample=["seed"]).sel(sample=2)["N"] == 50
    with pytest.raises(StoreError, match="has no attribute 'omega'"):
        combine_ensemble(paths, index=("omega",))


def test_combine_mixed_sizes_indexed_by_dimension(tmp_path):
    """Packings of different N and d combine into scalars only, indexed by (d, seed)."""
    paths = [save_packing(lattice_packing(name, 2), tmp_path / f"{name}.nc", attrs={"seed": 0})
             for name in ("triangular", "fcc")]
    ds = combine_ensemble(paths, index=("d", "seed"))
    assert list(ds["d"].values) == [2, 3] and "d" not in ds.data_vars
    assert list(ds["N"].values) == [4, 32] and "position" not in ds
