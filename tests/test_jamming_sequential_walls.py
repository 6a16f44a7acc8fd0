"""Algorithm 14 (sequential random loading) with hard walls and spherical containers.

The walls stay fixed (Donev 2006, sec. 4.4.2) and a wall contact is a contact with a fixed point of
the wall (sec. 4.4.3): in the LP a one-sided constraint n . dr_i <= h - r_i, in the step the exact
wall (:func:`hardpack.jamming.sequential.wall_step`). The verdicts of the small cases are derived in
tests/test_jamming_walls.py, where the ideal test (Algorithm 13) gives them.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_jamming_walls import flower_in_container, honeycomb_in_box

from hardpack.distributions import monodisperse
from hardpack.geometry.boundaries import HardWalls, SphericalContainer
from hardpack.geometry.packing import Packing
from hardpack.initial import random_packing
from hardpack.jamming import contact_network, verify
from hardpack.jamming.rigidity import rotation_velocities
from hardpack.jamming.sequential import APPROACH_SLACK, _mean_size, collision_step
from hardpack.md import StopCriteria, compress


def test_fig_4_4_honeycomb_in_a_hard_wall_box_unjams_under_sequential_loading():
    """Donev 2006, Fig. 4.4: the honeycomb Nc = (3, 2) between hard walls is locally jammed and
    hypostatic (M = 43 < N_f + 1 = 49), so it can be unjammed: a loading sequence moves it beyond
    the threshold along a flex that keeps every sphere inside the walls. The walls are fixed, so
    the strict test is the collective one."""
    p = honeycomb_in_box()
    r = verify(p, method="sequential", seed=1)
    assert r.verdicts == {"local": True, "collective": False, "strict": False}
    assert max(r.collective_test.mean_displacement) >= r.collective_test.threshold
    assert r.strict_test.method == "walls fixed: the collective test"
    assert r.collective_test.final.containment_report().n_outside == 0
    assert r.collective_test.final.overlap_report().n_overlapping == 0


@pytest.mark.parametrize("case", ["slot", "rods", "flower"])
def test_exactly_jammed_packings_with_walls_are_jammed_under_sequential_loading(case):
    """Two disks in a closed 2 x 1 slot, three rods filling [0, 3] between walls (d = 1), and seven
    disks filling a circular container (jammed up to its rotation, a trivial motion): each
    collectively jammed, and strictly with the walls fixed; no sequence moves anything."""
    p = {"slot": Packing([[0.5, 0.5], [1.5, 0.5]], [0.5, 0.5], np.diag([2.0, 1.0]), boundary=HardWalls([0, 1])),
         "rods": Packing([[0.5], [1.5], [2.5]], [0.5] * 3, [[3.0]], boundary=HardWalls([0])),
         "flower": flower_in_container()}[case]
    r = verify(p, method="sequential", seed=2)
    assert r.verdicts == {"local": True, "collective": True, "strict": True}
    assert max(r.collective_test.mean_displacement) < 1e-9
    assert r.strict_test.method == "walls fixed: the collective test"


def test_the_step_stops_at_a_flat_wall_and_at_the_container_wall():
    """A disk of radius 1/2 at height 1/2 + 1e-3 over the floor moving down at unit speed reaches
    the wall at tau = 1e-3 (less the approach slack); a sphere of radius 1/2 at distance 1 from the
    centre of a container of radius 1.501 moving tangentially at unit speed reaches the wall when
    1 + tau^2 = (R - r)^2, tau = sqrt(1.001^2 - 1). Only the exact wall stops it: the tangent plane
    of the linearised wall contact never would."""
    floor = Packing([[1.5, 0.5 + 1e-3]], [0.5], 3 * np.eye(2), boundary=HardWalls([0, 1]))
    net = contact_network(floor, 0.1)
    assert net.n_wall_contacts == 1
    assert collision_step(net, np.array([[0.0, -1.0]]), None) == pytest.approx(1e-3 + 0.5 * APPROACH_SLACK, rel=1e-9)
    assert collision_step(net, np.array([[1.0, 0.0]]), None) == np.inf  # parallel to the floor
    ball = Packing([[3.0, 2.0, 2.0]], [0.5], 4 * np.eye(3), boundary=SphericalContainer([2, 2, 2], 1.501))
    net = contact_network(ball, 0.1)
    assert net.n_wall_contacts == 1
    reach = 1.001 + 0.5 * APPROACH_SLACK
    assert collision_step(net, np.array([[0.0, 1.0, 0.0]]), None) == pytest.approx(np.sqrt(reach**2 - 1), rel=1e-9)


def test_a_rotation_in_a_container_is_no_displacement():
    """A rigid rotation about the container's centre is a trivial motion: the displacement
    relative to it is zero (the median subtraction of a periodic cell would leave it)."""
    p = flower_in_container()
    moving = np.ones(p.n_particles, dtype=bool)
    rotation = rotation_velocities(p.positions - np.array(p.boundary.centre)).reshape(-1, 2) * 1e-3
    assert _mean_size(rotation, moving, p) < 1e-15
    assert np.linalg.norm(rotation - np.median(rotation, axis=0), axis=1).mean() > 1e-4


def test_an_ls_packing_jammed_in_a_container_and_with_one_sphere_shrunk():
    """30 spheres compressed by LS inside a spherical container to Z = 1e12 with a slow final rate
    (3e-4): contacts at gaps < 1e-10, near contacts beyond 1e-5, so both methods say collectively
    jammed (strictly, the container fixed). Shrinking one backbone sphere by 10 % makes it a
    rattler; a backbone sphere is chosen whose neighbours stay locally jammed, so that the rest is
    hypostatic and the ideal test finds a floppy motion. The sequential test must not call that
    jammed: its straight steps are cut by the curved wall a few 1e-6 D into the LP motion, and it
    says undetermined (or not jammed)."""
    start = random_packing(30, 3, monodisperse(0.5), 0.2, seed=1, boundary="spherical_container")
    p = compress(start, 0.02, 1, stop=StopCriteria(max_pressure=1e12), final_growth_rate=3e-4).packing
    ideal, seq = verify(p), verify(p, method="sequential", seed=1)
    assert ideal.verdicts == seq.verdicts == {"local": True, "collective": True, "strict": True}
    assert seq.network.n_wall_contacts > 0
    for k in np.flatnonzero(~ideal.rattler):
        radii = p.radii.copy()
        radii[k] *= 0.9
        shrunk = p.replace(radii=radii)
        ideal = verify(shrunk, tests=("local", "collective"))
        if ideal.local:
            break
    else:
        pytest.skip("every shrunk sphere unjams the whole packing locally")
    assert ideal.rattler[k] and ideal.collective is False
    seq = verify(shrunk, method="sequential", seed=1, tests=("local", "collective"))
    assert seq.local_rattler[k] and seq.collective is not True
    if seq.collective is None:
        assert "container wall cut the step" in seq.undetermined["collective"]
