"""Compressions with very few particles inside hard walls: a particle alone in a spherical
container or a closed box, and two spheres in a container (degenerate but valid inputs).

- Exact values: one sphere of radius a moving freely in a container of radius R is an ideal gas of
  one point in a ball of radius rho = R - a; its momentum flux through the container wall is
  kT / V_rho spread over the area ratio (rho / R)^2, so Z_wall = p_w V / kT = R / rho exactly, and
  at the end of a compression stopped at Z_wall = P the volume fraction is (1 - 1 / P)^3 in 3D.
  One ellipsoid (ellipse) fills the container when its largest semiaxis reaches R: phi = b c / a^2
  (b / a in 2D). Two equal spheres jam against each other and the wall at a = R / 2: phi = 1 / 4.
- Before these inputs were handled, the engine refused a particle larger than a quarter of the
  box side (a rule of periodic images, which walled axes do not have) and the pair pressure Z = 1
  of a lone particle never reached max_pressure. The wall-time stop (600 s, which includes a cold
  numba compilation) only ends a run that would otherwise never stop.
"""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.geometry.boundaries import HardWalls, SphericalContainer
from hardpack.geometry.packing import Packing
from hardpack.md import StopCriteria, compress


def _alone_in_a_container(d=3, radius=1.0):
    box = np.diag([20.0] * d)
    return Packing(np.array([[10.0] * d]), np.array([radius]), box,
                   boundary=SphericalContainer((10.0,) * d, 10.0))


def test_a_sphere_alone_in_a_container_fills_it_and_stops_on_the_wall_pressure():
    res = compress(_alone_in_a_container(), 0.1, 1, stop=StopCriteria(max_pressure=1e6, max_wall_time=600))
    s = res.stats
    assert s["stop_reason"] == "max_pressure" and s["collisions"] == 0
    assert s["Z"] == 1.0 and s["Z_wall"] >= 1e6
    # Z_wall = R / (R - a): 1 - phi = 1 - (1 - 1 / Z_wall)^3 ~ 3 / Z_wall (the last window's
    # estimate of Z_wall during growth: within a few percent)
    assert (1.0 - s["phi"]) * s["Z_wall"] == pytest.approx(3.0, rel=0.05)
    assert s["jamming_check"] == "passed"  # it touches the wall all round
    assert res.packing.containment_report().n_outside == 0


def test_a_sphere_alone_in_a_closed_box_jams_at_the_inscribed_ball():
    box = np.diag([4.0, 4.0, 4.0])
    p = Packing(np.array([[2.0, 2.0, 2.0]]), np.array([0.5]), box, boundary=HardWalls((0, 1, 2)))
    res = compress(p, 0.1, 1, stop=StopCriteria(max_pressure=1e6, max_wall_time=600))
    assert res.stats["stop_reason"] == "max_pressure" and res.stats["Z_wall"] >= 1e6
    assert res.stats["phi"] == pytest.approx(np.pi / 6, rel=1e-4)  # the ball inscribed in the cube


def test_two_spheres_in_a_container_touch_each_other_and_the_wall_at_half_its_radius():
    box = np.diag([20.0, 20.0, 20.0])
    p = Packing(np.array([[7.0, 10, 10], [13.0, 10, 10]]), np.array([1.0, 1.0]), box,
                boundary=SphericalContainer((10.0, 10, 10), 10.0))
    res = compress(p, 0.1, 1, stop=StopCriteria(max_pressure=1e6, max_wall_time=600))
    assert res.stats["stop_reason"] == "max_pressure" and res.stats["Z"] >= 1e6
    assert res.stats["phi"] == pytest.approx(0.25, rel=1e-4)
    # the pair can still turn about the centre as a dumbbell: not jammed, and the check says so
    assert res.stats["jamming_check"] == "far_from_jammed"


@pytest.mark.parametrize("d", [3, 2])
def test_an_ellipsoid_alone_in_a_container_grows_until_its_long_semiaxis_reaches_the_wall(d):
    from hardpack.geometry.shapes import Ellipsoids
    from hardpack.md.ellipsoid import compress_ellipsoids

    axes = np.array([[2.0, 1.0, 1.0]]) if d == 3 else np.array([[2.0, 1.0]])
    orientation = np.array([[1.0, 0, 0, 0]]) if d == 3 else np.array([0.3])
    p = Packing(np.array([[10.0] * d]), lattice=np.diag([20.0] * d), shape=Ellipsoids(axes, orientation),
                boundary=SphericalContainer((10.0,) * d, 10.0))
    res = compress_ellipsoids(p, 0.1, 1, stop=StopCriteria(max_pressure=1e6, max_wall_time=600))
    assert res.stats["stop_reason"] == "max_pressure"
    # below the limit by more than a sphere (3 / Z_wall): a move across the long axis meets the
    # wall only at second order, so the free volume closes more slowly (1 - phi / phi_J ~ 2e-4 at
    # Z_wall = 1e6)
    assert 0.0 < 1.0 - res.stats["phi"] / (0.25 if d == 3 else 0.5) < 1e-3
