"""Random-start searches for dense spheroid crystals in small deforming cells (hardpack.md.crystal_search).

Physics checked:
- four spheroids 1 : 1 : sqrt 3 per cell, from a random start, order at the isobaric stage and
  jam at Donev's densest laminate (SM2), phi = 0.770732 with 14 contacts on every particle
  (Donev 2006, sec. 8.2; the laminate built independently by
  :func:`hardpack.geometry.ellipsoid_crystals.laminate`);
- one spheroid per cell ends at (seed 0) or below the densest lattice packing, phi = pi / sqrt(18),
  which is not the laminate (the search reports no match), through the command line;
- bad input is refused.
"""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.md.crystal_search import crystal_search, laminate_reference, search_run

SQRT3 = float(np.sqrt(3.0))


def test_laminate_reference_is_donevs_densest_crystal():
    phi, contacts = laminate_reference(SQRT3)
    assert phi == pytest.approx(0.770732, abs=1e-6)
    assert contacts == 14
    assert laminate_reference(1 / SQRT3) == pytest.approx((phi, contacts))


@pytest.mark.slow
def test_four_spheroids_per_cell_find_the_laminate():
    run = search_run(4, SQRT3, 0)
    assert run["phi"] == pytest.approx(0.770732, abs=1e-5)
    assert run["min_contacts"] == run["max_contacts"] == 14
    assert run["n_overlapping"] == 0
    assert run["phi_equilibrated"] < 0.7  # it started as a fluid-like random packing and ordered


def test_cli_search_with_one_spheroid_per_cell(tmp_path):
    from hardpack.cli import main
    from hardpack.io import load_dataset

    out = tmp_path / "search.nc"
    assert main(["crystal-search", "--alpha", str(SQRT3), "--n", "1", "--seeds", "0", "2",
                 "--out", str(out)]) == 0
    ds = load_dataset(out)
    assert ds["phi"].shape == (1, 2)
    # seed 0 reaches the densest lattice packing, seed 2 jams its cell early; none beats it
    assert ds["phi"].values[0, 0] == pytest.approx(np.pi / np.sqrt(18.0), abs=2e-5)
    assert (ds["phi"] < np.pi / np.sqrt(18.0) + 1e-7).all()
    assert not ds["laminate"].values.any()
    assert ds.attrs["phi_laminate"] == pytest.approx(0.770732, abs=1e-6)
    assert (ds["n_overlapping"] == 0).all()


def test_bad_input_is_refused():
    with pytest.raises(InvalidInputError, match="integer >= 1"):
        search_run(0, SQRT3, 0)
    with pytest.raises(InvalidInputError, match="aspect ratio"):
        search_run(2, -1.0, 0)
    with pytest.raises(InvalidInputError, match="pressure"):
        search_run(2, SQRT3, 0, pressure=0.0)
    with pytest.raises(InvalidInputError, match="seed"):
        crystal_search([2], SQRT3, [])
