"""Figures of the ellipsoid study: the shadow geometry of the snapshot and the phi_J / Z panels."""

import math

import numpy as np
import pytest
import xarray as xr

from hardpack.geometry import Ellipsoids, Packing
from hardpack.geometry.ellipsoid_crystals import laminate
from hardpack.plots.ellipsoids import _shadow, plot_jamming_vs_alpha, plot_snapshot
from hardpack.plots.style import save


def test_shadow_of_a_turned_ellipsoid_is_its_projection():
    """Semiaxes (3, 1, 2) turned by 30 degrees about z: the xy shadow has semiaxes 3 and 1 at 30
    degrees; turned by 90 degrees about x instead, the y extent is the third semiaxis, 2."""
    half = math.radians(30) / 2
    p = Packing([[5.0, 5.0, 5.0]], lattice=np.eye(3) * 10,
                shape=Ellipsoids([[3.0, 1.0, 2.0]], [[math.cos(half), 0, 0, math.sin(half)]]))
    widths, heights, angles = _shadow(p)
    assert (widths[0], heights[0]) == pytest.approx((6.0, 2.0))
    assert np.mod(angles[0], 180) == pytest.approx(30.0)
    quarter = math.pi / 4
    q = Packing([[5.0, 5.0, 5.0]], lattice=np.eye(3) * 10,
                shape=Ellipsoids([[3.0, 1.0, 2.0]], [[math.cos(quarter), math.sin(quarter), 0, 0]]))
    widths, heights, _ = _shadow(q)
    assert sorted([widths[0], heights[0]]) == pytest.approx([4.0, 6.0])


def test_figures_are_written(tmp_path):
    rng = np.random.default_rng(0)
    rows = [(b, a, s) for b in (0.0, 0.5, 1.0) for a in (1.0, 1.5, 2.0) for s in (1, 2)]
    beta, alpha, seed = (np.array(v) for v in zip(*rows))
    summary = xr.Dataset({"beta": ("sample", beta), "alpha": ("sample", alpha), "seed": ("sample", seed),
                          "phi": ("sample", 0.64 + 0.1 * (alpha - 1) + rng.normal(0, 0.002, len(rows))),
                          "z_mean": ("sample", 6 + 4 * np.sqrt(alpha - 1))})
    save(plot_jamming_vs_alpha(summary), tmp_path / "a.pdf")
    save(plot_snapshot(laminate(1.5).tiled((4, 4, 3))), tmp_path / "b.png")
    disks = Packing([[0.5, 0.5], [1.5, 0.5]], lattice=np.eye(2) * 2,
                    shape=Ellipsoids([[0.45, 0.3], [0.45, 0.3]], [0.0, 1.0]))
    save(plot_snapshot(disks), tmp_path / "c.png")
    assert all((tmp_path / n).stat().st_size > 1000 for n in ("a.pdf", "b.png", "c.png"))
