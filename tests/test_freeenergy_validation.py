"""Validation rows of the BCMD study (hardpack.validation.freeenergy) on synthetic summaries."""

import numpy as np
import pytest
import xarray as xr

from hardpack.freeenergy.crystal import free_volume_z
from hardpack.validation.freeenergy import density_rows, ladder_rows, simplex_rows


def simplex_summary(rel, iso=1):
    n = np.array([126, 126])
    exact = np.array([4.977, 4.977 + 3 * np.log(126) / 126])
    return xr.Dataset(
        {"exact": ("sample", exact), "bcmd": ("sample", exact * (1 + np.asarray(rel))),
         "rel_diff": ("sample", np.asarray(rel, float)), "isostatic": ("sample", [iso, iso]),
         "isostaticity_gap": ("sample", [0, 0] if iso else [5, 5]), "n_backbone": ("sample", n),
         "dim": ("sample", [3, 3]), "n_events": ("sample", [10, 10]),
         "seconds_bcmd": ("sample", [1.0, 1.0])},
        coords={"seed": ("sample", [1, 1]), "frozen": ("sample", ["particle", "cm"])},
    )


def test_simplex_rows():
    rows = simplex_rows(simplex_summary([0.002, -0.008]))
    assert [r.passed for r in rows] == [True, True]
    assert rows[1].published == pytest.approx(4.977 + 3 * np.log(126) / 126)
    assert [r.passed for r in simplex_rows(simplex_summary([0.002, -0.02]))] == [True, False]
    rows = simplex_rows(simplex_summary([np.nan, np.nan], iso=0))
    assert not any(r.passed for r in rows) and "no isostatic" in rows[0].detail


def test_density_row_compares_bcmd_with_the_eos_integral():
    # BCMD excesses that follow the free-volume pressure exactly pass; a 0.02 offset fails
    phi = np.array([0.545, 0.6, 0.65, 0.7, 0.73])
    x = (phi / (np.pi / np.sqrt(18))) ** (1 / 3)
    exact = 6.0 - 3 * np.log((1 - x) / (1 - x[0]))
    eos = xr.Dataset({"Z": ("sample", free_volume_z(phi)), "N": ("sample", [108] * 5),
                      "wall_time": ("sample", [1.0] * 5)}, coords={"phi": ("sample", phi)})

    def bcmd(excess):
        return xr.Dataset({"excess": ("sample", excess), "n_particles": ("sample", [108] * 5),
                           "n_events": ("sample", [1] * 5), "seconds": ("sample", [1.0] * 5)},
                          coords={"phi": ("sample", phi), "seed": ("sample", [1] * 5)})

    row = density_rows(bcmd(exact), eos)[0]
    assert row.passed and row.reproduced == pytest.approx(row.published, abs=1e-9)
    assert not density_rows(bcmd(exact + np.r_[0, 0, 0, 0, 0.02]), eos)[0].passed


def test_ladder_rows():
    ds = xr.Dataset({"value": ("check", [1.004, 0.5]), "exact": ("check", [1.0, 1.0]),
                     "tolerance": ("check", [0.01, 0.01]), "why": ("check", ["x", "y"]),
                     "seconds": ("check", [1.0, 1.0])},
                    coords={"check": ["a", "b"]})
    assert [r.passed for r in ladder_rows(ds)] == [True, False]
