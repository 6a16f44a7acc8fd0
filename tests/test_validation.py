"""Validation report: rows, pass/fail logic, formats, and the analytic rows it always contains."""

import math

import numpy as np
import pytest

from hardpack.cli import main
from hardpack.io import load_dataset, save_packing
from hardpack.geometry import lattice_packing
from hardpack.validation import Row, to_dataset, to_markdown
from hardpack.validation.analytic import moment_table_rows
from hardpack.validation.rows import within
from hardpack.validation.slp import densest_rows
from hardpack.io import combine_ensemble


def test_within_uses_tolerance_plus_two_standard_errors():
    assert within(1.004, 1.0, 0.005)
    assert not within(1.006, 1.0, 0.005)
    assert within(1.006, 1.0, 0.005, uncertainty=0.001)
    assert not within(math.nan, 1.0, 1.0)


def test_moment_tables_all_reproduced():
    rows = moment_table_rows()
    assert len(rows) == 9 + 9 + 7 + 20  # one row per printed line of Tables 3.1 (US, UV), 3.3, 3.4
    assert all(r.passed for r in rows), [r.quantity for r in rows if not r.passed]


def test_a_wrong_value_fails_and_is_reported():
    rows = [Row("s", "good", "src L1", 1.0, 1.0, math.nan, 0.1, "why", True),
            Row("s", "bad", "src L2", 1.0, 2.0, 0.01, 0.1, "why", False, "detail")]
    md = to_markdown(rows)
    assert "1 of 2 rows pass (50%)" in md and "| **no** |" in md
    ds = to_dataset(rows)
    assert ds.attrs["n_passed"] == 1 and list(ds["passed"].values) == [1, 0]
    assert ds["quantity"].values[1] == "bad" and np.isnan(ds["uncertainty"].values[0])


def test_densest_rows_from_a_summary(tmp_path):
    # a perfect triangular packing counts as a hit; an off-density one as a miss
    good = save_packing(lattice_packing("triangular", 3), tmp_path / "a.nc", attrs={"seed": 0})
    bad = save_packing(lattice_packing("square", 3), tmp_path / "b.nc", attrs={"seed": 1})
    rows = densest_rows(combine_ensemble([good, bad], index=("d", "seed")))
    assert len(rows) == 1 and rows[0].passed and "1 of 2 seeds" in rows[0].detail
    rows = densest_rows(combine_ensemble([bad], index=("d", "seed")))
    assert not rows[0].passed


@pytest.mark.slow
def test_cli_writes_table_and_report(tmp_path):
    nc, md = tmp_path / "v.nc", tmp_path / "r.md"
    assert main(["validate", "--out-nc", str(nc), "--out-md", str(md)]) == 0
    ds = load_dataset(nc, kind="validation")
    assert ds.sizes["row"] >= 48 and ds.attrs["n_passed"] == ds.sizes["row"]
    assert md.read_text().startswith("# hardpack validation report")


def test_bcmd_rows_need_a_finite_size_extrapolation():
    import xarray as xr
    from hardpack.validation.freeenergy import bcmd_rows, finite_size_extrapolation

    n = np.array([108, 256, 500, 864])
    exact = 5.91916 - 3 * np.log(n) / n  # a + b ln N / N with a = the published value
    est, err, how = finite_size_extrapolation(n, exact)
    assert est == pytest.approx(5.91916, abs=1e-9) and "fit" in how
    ds = xr.Dataset({"n_particles": ("sample", n), "excess": ("sample", exact)})
    assert bcmd_rows({"melting": ds})[0].passed
    small = ds.isel(sample=[0, 1])
    row = bcmd_rows({"melting": small})[0]
    assert not row.passed and "inconclusive" in row.detail


def test_validate_inputs_are_name_equals_path_with_known_names():
    from hardpack.errors import InvalidInputError
    from hardpack.validation.cli import parse_inputs

    assert parse_inputs(["ls=a.nc", "bcmd=b.nc", "ls=c.nc"]) == {"ls": ["a.nc", "c.nc"], "bcmd": ["b.nc"]}
    with pytest.raises(InvalidInputError, match="NAME=PATH"):
        parse_inputs(["a.nc"])
    with pytest.raises(InvalidInputError, match="unknown validation input name 'lss'"):
        parse_inputs(["lss=a.nc"])


def _jamming_summary(z, rattlers, collective, d=3, kind="monodisperse"):
    import json

    import xarray as xr

    n = len(z)
    ds = xr.Dataset({"N": ("sample", [1000] * n), "d": ("sample", [d] * n), "z_mean": ("sample", z),
                     "rattler_fraction": ("sample", rattlers), "isostaticity_gap": ("sample", [1] * n),
                     "collective": ("sample", collective)})
    spec = {"kind": kind} if kind == "monodisperse" else {"kind": kind, "size_ratio": 1.4, "large_fraction": 0.5}
    ds.attrs.update(ensemble="e", distribution=json.dumps(spec))
    return ds


def test_jamming_rows_pass_for_isostatic_packings_and_fail_otherwise():
    from hardpack.validation.jamming import jamming_rows

    good = jamming_rows([_jamming_summary([5.99, 6.0, 5.995], [0.02, 0.025, 0.021], [1, 1, 1])])
    assert [r.passed for r in good] == [True, True, True]
    # hypostatic (fast single-stage LS), too many rattlers, one seed not collectively jammed
    bad = jamming_rows([_jamming_summary([5.8, 5.85, 5.82], [0.05, 0.06, 0.05], [1, 0, 1])])
    assert [r.passed for r in bad] == [False, False, False]
    disks = jamming_rows([_jamming_summary([4.0, 3.99], [0.05, 0.04], [1, 1], d=2, kind="bidisperse")])
    assert [r.published for r in disks] == [4.0, 1.0] and all(r.passed for r in disks)


def test_structure_rows_on_a_bcc_crystal_fail_the_amorphous_signatures():
    """BCC (shells 1, 1.155, 1.633, 1.915, 2) has no sub-peak at sqrt(3) and no near-contact power
    law: those rows must fail. The CS fluid S(0) is the
    compressibility-route value."""
    from hardpack.structure.analysis import analyse
    from hardpack.validation.structure import fluid_s0, structure_rows

    from hardpack.eos.theory import carnahan_starling

    # compressibility route: S(0) = 1 / d(phi Z)/d phi, by a central difference of the CS EOS
    h = 1e-6
    for phi in (0.1, 0.49, 0.64):
        slope = ((phi + h) * carnahan_starling(phi + h) - (phi - h) * carnahan_starling(phi - h)) / (2 * h)
        assert fluid_s0(phi) == pytest.approx(1 / slope, rel=1e-7)
    ds = analyse(lattice_packing("bcc", (4, 4, 4)), channels=False, order=False)
    ds.attrs["source"] = "results/ensembles/bcc/jammed/seed1.nc"
    rows = {r.quantity.split(": ")[1]: r for r in structure_rows([ds])}
    assert not rows["near-contact exponent alpha, rattlers removed"].passed
    assert not rows["g2 second-peak sub-peak at sqrt(3) D"].passed
