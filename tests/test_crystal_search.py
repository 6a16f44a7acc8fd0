"""Random-start searches for dense spheroid crystals in small deforming cells (hardpack.md.crystal_search).

Physics checked:
- four spheroids 1 : 1 : sqrt 3 per cell, from random starts, never end denser than Donev's
  densest laminate (SM2, phi = 0.770732; Donev 2006, sec. 8.2; built independently by
  :func:`hardpack.geometry.ellipsoid_crystals.laminate`), and some find its network, 14 contacts
  on every particle, at phi ~ 0.7707 as printed for the search;
- one spheroid per cell ends at (some seeds) or below the densest lattice packing, phi = pi / sqrt(18),
  which is not the laminate (the search reports no match), through the command line; polished in
  the deforming cell by the size ascent, every run reaches pi / sqrt(18);
- the polish takes the four-per-cell runs with the laminate's contacts to phi = 0.770732;
- the validation rows judge the densest run at sqrt 3 against Donev's phi ~ 0.7707 and 14 contacts,
  and the laminate figure draws every run;
- bad input is refused (also spheres, alpha = 1, whose own-image contact no spin can resolve).
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
    # beyond sqrt(3) the densest known crystal is the stretched laminate: 0.770732 and 14 contacts
    # (Donev 2006, Sec. 8.2, Fig. 8.2), not the unstretched laminate of that alpha (0.6856 at 2)
    assert laminate_reference(2.0) == pytest.approx((phi, 14), abs=1e-6)
    assert laminate_reference(1 / 3.0) == pytest.approx((phi, 14), abs=1e-6)
    assert laminate_reference(1.5)[0] == pytest.approx(0.7534, abs=5e-5)


@pytest.mark.slow
def test_four_spheroids_per_cell_find_the_laminate():
    # a claim over seeds (which seed finds what depends on the host's last bits): one of seeds
    # 0-3 finds the laminate's contact network (14 on every particle) at Donev's phi ~ 0.7707 for
    # the search, to its printed digits, and no run before it is denser than the laminate
    # (measured on seeds 0-3: two at 0.770720 and 0.770700 with 14 contacts, two at 0.74045 with
    # 12, the affine FCC). The seeds stop at the first that finds it: the best of all four is the
    # smoke DAG's (the same runs, validation rows donev-8.2-search-*)
    found = 0
    for seed in range(4):
        run = search_run(4, SQRT3, seed)
        assert run["phi"] < 0.770732 + 1e-6
        assert run["n_overlapping"] == 0
        assert run["phi_equilibrated"] < 0.7  # it started as a fluid-like random packing
        if run["min_contacts"] == run["max_contacts"] == 14:
            assert run["phi"] == pytest.approx(0.7707, abs=5e-5)
            found += 1
            # the polish in the deforming cell reaches the laminate itself, to Donev's 6 digits
            assert run["phi_polished"] == pytest.approx(0.770732, abs=5e-7)
            assert run["min_contacts_polished"] == run["max_contacts_polished"] == 14
        assert run["phi"] - 1e-9 < run["phi_polished"] < 0.770732 + 1e-6
        if found:
            break
    assert found >= 1


def test_cli_search_with_one_spheroid_per_cell(tmp_path):
    from hardpack.cli import main
    from hardpack.io import load_dataset

    out = tmp_path / "search.nc"
    assert main(["crystal-search", "--alpha", str(SQRT3), "--n", "1", "--seeds", "0", "1",
                 "--out", str(out)]) == 0
    ds = load_dataset(out)
    assert ds["phi"].shape == (1, 2)
    # a seed may jam its cell early (which one depends on the host's last bits; both reached the
    # densest lattice packing here): the claim over four seeds is
    # tests/test_md_deforming_ellipsoids.py::test_one_spheroid_per_cell_ends_at_the_densest_lattice_packing,
    # the same runs; none beats it
    assert float(ds["phi"].max()) == pytest.approx(np.pi / np.sqrt(18.0), abs=2e-5)
    assert (ds["phi"] < np.pi / np.sqrt(18.0) + 1e-7).all()
    assert not ds["laminate"].values.any()
    assert ds.attrs["phi_laminate"] == pytest.approx(0.770732, abs=1e-6)
    assert (ds["n_overlapping"] == 0).all()
    # polished in the deforming cell, every run reaches the densest lattice packing, the only local
    # maximum of the lattice density (tests/test_jamming_ascent.py), with 12 contacts
    assert np.abs(ds["phi_polished"] - np.pi / np.sqrt(18.0)).max() < 1e-8
    assert (ds["min_contacts_polished"] == 12).all() and (ds["max_contacts_polished"] == 12).all()
    assert ds.attrs["phi_best_polished"] == pytest.approx(np.pi / np.sqrt(18.0), abs=1e-8)


def test_bad_input_is_refused():
    with pytest.raises(InvalidInputError, match="integer >= 1"):
        search_run(0, SQRT3, 0)
    with pytest.raises(InvalidInputError, match="aspect ratio"):
        search_run(2, -1.0, 0)
    with pytest.raises(InvalidInputError, match="pressure"):
        search_run(2, SQRT3, 0, pressure=0.0)
    with pytest.raises(InvalidInputError, match="seed"):
        crystal_search([2], SQRT3, [])
    with pytest.raises(InvalidInputError, match="own periodic images"):
        search_run(1, 1.0, 0)


def _search(alpha, ns, phi, contacts, polished=None):
    """A search dataset with given phi and mean contacts on (n, seed), shaped as crystal_search's;
    ``polished`` phi with the same contacts, or none (a search without the polish)."""
    import xarray as xr

    phi, contacts = np.asarray(phi, float), np.asarray(contacts, float)
    lam = (np.abs(phi - 0.7707316) < 1e-4) & (contacts == 14)
    data = {"phi": (("n", "seed"), phi), "Z": (("n", "seed"), np.full(phi.shape, 1e9)),
            "contacts": (("n", "seed"), contacts), "min_contacts": (("n", "seed"), contacts),
            "max_contacts": (("n", "seed"), contacts), "laminate": (("n", "seed"), lam)}
    if polished is not None:
        polished = np.asarray(polished, float)
        data.update({"phi_polished": (("n", "seed"), polished),
                     "min_contacts_polished": (("n", "seed"), contacts),
                     "max_contacts_polished": (("n", "seed"), contacts),
                     "laminate_polished": (("n", "seed"), (np.abs(polished - 0.7707316) < 1e-4) & (contacts == 14))})
    return xr.Dataset(data, coords={"n": ns, "seed": np.arange(phi.shape[1])}, attrs={"alpha": alpha})


def test_search_rows_judge_the_best_run_against_donevs_search():
    from hardpack.validation.ellipsoids import crystal_search_rows

    found = _search(SQRT3, [2, 4], [[0.7704, 0.7405], [0.770729, 0.7381]], [[12, 12], [14, 12]],
                    polished=[[0.7705, 0.7404805], [0.7707316, 0.7404805]])
    assert [r.status for r in crystal_search_rows([found])] == ["pass", "pass", "pass", "n/a"]
    # polished 0.770731 is 1e-6 off the printed 0.770732 (6 digits): fails; unpolished: n/a
    short = _search(SQRT3, [4], [[0.770729, 0.7381]], [[14, 12]], polished=[[0.770731, 0.7404805]])
    assert [r.status for r in crystal_search_rows([short])] == ["pass", "pass", "fail", "n/a"]
    fcc_only = _search(SQRT3, [4], [[0.740480, 0.7381]], [[12, 10]])
    assert [r.status for r in crystal_search_rows([fcc_only])] == ["fail", "fail", "n/a", "n/a"]
    # the second-best laminate-like run of phi 0.77064 is 9e-5 off the printed 0.7707: fails
    near = _search(SQRT3, [4], [[0.77064, 0.7381]], [[14, 10]])
    assert [r.status for r in crystal_search_rows([near])] == ["fail", "pass", "n/a", "n/a"]
    one_per_cell = _search(SQRT3, [1], [[0.740480]], [[12]], polished=[[0.7404805]])
    assert [r.status for r in crystal_search_rows([one_per_cell])] == ["n/a", "n/a", "n/a", "n/a"]
    elsewhere = _search(1.5, [4], [[0.7573]], [[12]])
    assert [r.status for r in crystal_search_rows([elsewhere])] == ["n/a", "n/a", "n/a", "n/a"]
    # the oblate laminate (alpha = 1/sqrt(3)) has the same maximum; its row judges the polished run only
    oblate = _search(1 / SQRT3, [2, 4], [[0.7404, 0.7405], [0.7071, 0.6986]], [[12, 12], [12, 14]],
                     polished=[[0.7404805, 0.7404805], [0.7404805, 0.7707316]])
    rows = crystal_search_rows([found, oblate])
    assert [r.status for r in rows] == ["pass", "pass", "pass", "pass"] and rows[3].label == "alpha = 1/sqrt(3)"
    cut_short = _search(1 / SQRT3, [4], [[0.7071, 0.6986]], [[12, 12]], polished=[[0.7404805, 0.7687773]])
    assert crystal_search_rows([found, cut_short])[3].status == "fail"


def test_laminate_figure_shows_the_search_runs():
    from hardpack.geometry.ellipsoid_crystals import laminate_family
    from hardpack.plots.ellipsoids import plot_laminate_family

    found = _search(SQRT3, [2, 4], [[0.7704, 0.7405], [0.770729, 0.7381]], [[12, 12], [14, 12]])
    fig = plot_laminate_family(laminate_family([1.0, 1.5, SQRT3, 2.0]), [found])
    points = [line for line in fig.axes[1].lines if len(line.get_xdata()) and line.get_marker() in "sD"]
    plotted = np.sort(np.concatenate([line.get_ydata() for line in points]))
    assert plotted == pytest.approx(np.sort([0.7704, 0.7405, 0.770729, 0.7381]))
    assert {"2 per cell", "4 per cell"} <= {t.get_text() for t in fig.axes[1].get_legend().get_texts()}
