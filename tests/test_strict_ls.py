"""Deforming-cell LS study rows (Donev 2006, Sec. 4.7.2.3): the fraction of strictly jammed
packings against "typically strictly jammed"."""

import xarray as xr

from hardpack.validation.jamming import strict_ls_rows


def _verdicts(d, n, strict):
    k = len(strict)
    return xr.Dataset({"N": ("sample", [n] * k), "d": ("sample", [d] * k), "strict": ("sample", strict)},
                      coords={"seed": ("sample", list(range(k)))}, attrs={"ensemble": f"strict_ls_d{d}", "d": d})


def test_strict_rows_pass_when_most_packings_are_strict_and_fail_otherwise():
    (row,) = strict_ls_rows([_verdicts(2, 20, [1, 1, 1])])
    assert row.target == "donev-4.7.2.3-deforming-ls-strict-d2" and row.status == "pass" and row.reproduced == 1
    (row,) = strict_ls_rows([_verdicts(3, 30, [1, 0, 0])])
    assert row.target == "donev-4.7.2.3-deforming-ls-strict-d3" and row.status == "fail"
    assert row.reproduced == 1 / 3 and "strict verdicts 1, 0, 0" in row.detail
    (row,) = strict_ls_rows([_verdicts(3, 30, [1, -2, 1])])  # an undetermined verdict is not strict
    assert row.reproduced == 2 / 3 and "undetermined" in row.detail


def test_strict_rows_skip_dimensions_without_a_target():
    assert strict_ls_rows([_verdicts(5, 30, [1])]) == []


def test_jammed_disk_figure_counts_rattlers_and_saves(tmp_path):
    import numpy as np

    from hardpack.geometry import lattice_packing
    from hardpack.plots.jamming import plot_jammed_disks
    from hardpack.plots.style import save

    crystal = lattice_packing("triangular", [2, 2])
    n = crystal.n_particles
    verdict = xr.Dataset({"contact_i": ("contact", [0, 1]), "contact_j": ("contact", [1, 2]),
                          "contact_shift": (("contact", "dim"), np.zeros((2, 2), int)),
                          "force": ("contact", [1.0, 0.5]), "rattler": ("particle", [False] * (n - 1) + [True])},
                         attrs={"verdict": "strictly jammed"})
    fig = plot_jammed_disks(crystal, verdict)
    assert "1 rattlers" in fig.axes[0].get_title()
    save(fig, tmp_path / "disks.pdf")
    assert (tmp_path / "disks.pdf").stat().st_size > 0
