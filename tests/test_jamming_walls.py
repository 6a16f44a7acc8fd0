"""Jamming tests with hard walls and spherical containers (Donev 2006, secs. 4.4.2-4.4.3).

A wall contact is a contact with a fixed point of the wall: n . dr_i <= h - r_i for a sphere at
centre-wall distance h from a wall with outward normal n. Every verdict below is derived by hand
in the test's docstring, or is the one the text gives (Fig. 4.4).
"""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.geometry.boundaries import HardWalls, SphericalContainer
from hardpack.geometry.packing import Packing
from hardpack.jamming import contact_network, rigidity_matrix, verify

SQ3 = np.sqrt(3.0)


def honeycomb_in_box(cells=(3, 2)) -> Packing:
    """Disks of diameter 1 on the honeycomb lattice (bond length 1), ``cells`` rectangular unit
    cells of 4 disks (width sqrt 3 along the zigzag rows, height 3) in a hard-wall box whose four
    walls touch the outer disks (Donev 2006, Fig. 4.4: Nc = (3, 2)).

    The patch is 2 cells[1] zigzag rows (along x) of 2 cells[0] disks; the disks of row k sit at
    x = m sqrt(3)/2 and alternate between a low and a high height (difference 1/2); each row's
    high disks are bonded vertically (length 1) to the low disks of the row above, so the rows
    alternate in phase. The bottom wall touches the low disks of the bottom row, the top wall the
    high disks of the top row, the side walls the first and last disk of every row. Each disk
    then keeps at least d + 1 = 3 contacts that positively span the plane (a wall replaces each
    missing honeycomb neighbour on the correct side), so every disk is locally jammed.
    """
    nx, ny = 2 * cells[0], 2 * cells[1]
    pos = []
    for k in range(ny):
        base = 1.5 * k  # low height of row k: rows are 1/2 (zigzag) + 1 (bond) apart
        for m in range(nx):
            high = (m + k) % 2 == 1
            pos.append((m * SQ3 / 2, base + 0.5 * high))
    pos = np.array(pos) + 0.5
    width, height = (nx - 1) * SQ3 / 2 + 1.0, 1.5 * (ny - 1) + 0.5 + 1.0
    return Packing(pos, np.full(len(pos), 0.5), np.diag([width, height]), boundary=HardWalls([0, 1]))


def _first_order_ok(result) -> np.ndarray:
    """A^T v over every contact (walls included) of the collective unjamming motion v."""
    a = rigidity_matrix(result.network)
    return a.T @ result.collective_test.motion.ravel()


def test_fig_4_4_honeycomb_in_a_hard_wall_box_is_locally_but_not_collectively_jammed():
    """Donev 2006, Fig. 4.4 and sec. 4.4.2: the honeycomb Nc = (3, 2) in a hard-wall rectangular
    container "can be unjammed". Counting (sec. 4.3.1.1, hard walls: N_f = N d, wall contacts
    counted in M): N = 24 disks, 29 disk contacts (4 rows of 5 zigzag bonds, 3 x 3 vertical
    bonds) and 14 wall contacts (3 bottom, 3 top, 4 on each side): M = 43 < N_f + 1 = 49, so the
    packing is hypostatic and cannot be collectively jammed, while each disk is locally jammed
    (construction in :func:`honeycomb_in_box`; Torquato & Stillinger's hard-wall classification,
    quoted in Donev 2006, sec. 4.7.1: the honeycomb is locally but not collectively jammed).
    Strict jamming needs collective jamming (sec. 4.2.2)."""
    p = honeycomb_in_box()
    assert p.n_particles == 24
    r = verify(p)
    net = r.network
    assert net.n_contacts - net.n_wall_contacts == 29 and net.n_wall_contacts == 14
    assert sorted(np.bincount(net.wall[net.is_wall])) == [3, 3, 4, 4]
    assert r.local is True and not r.local_rattler.any()
    assert r.collective is False and r.strict is False
    assert r.statics.n_dof_collective == 48 and r.statics.isostaticity_gap == 43 - 48 - 1
    # the unjamming motion: a first-order flex that opens no contact, wall contacts included
    v = r.collective_test.motion
    assert np.linalg.norm(v, axis=1).max() >= r.params["dr_large"]
    assert _first_order_ok(r).min() >= -1e-9 * np.abs(v).max()
    ds = r.to_dataset()
    assert ds.attrs["collective"] == 0 and ds.attrs["n_wall_contacts"] == 14
    assert int((ds["contact_wall"].values >= 0).sum()) == 14


def test_the_fig_4_4_disks_without_walls_are_all_rattlers():
    """The same 24 disks without the walls (periodic box of the same size, where the disks do
    not touch their images): no wall contacts, so each boundary disk has at most 2 contacts and
    the local test removes every disk (all rattlers) -- the walls are what jam the disks
    locally in Fig. 4.4."""
    p = honeycomb_in_box()
    free = Packing(p.positions, p.radii, p.lattice + np.diag([1.0, 1.0]))
    r = verify(free)
    assert r.local is False and r.local_rattler.all()


@pytest.mark.parametrize("walls", [[0, 1], [1]])
def test_a_disk_wedged_between_two_parallel_walls_slides_along_them(walls):
    """One disk of radius 1/2 at (1.5, 0.5) in a box 3 x 1 (walls on both axes, or only on
    y = 0 and y = 1 with x periodic). It touches the walls y = 0 and y = 1: normals -e_y and +e_y,
    constraints -dy <= 0 and dy <= 0, so dy = 0 and dx is free (up to the side walls at gap 1):
    2 contacts < d + 1, not locally jammed -- a rattler, and nothing is jammed."""
    p = Packing([[1.5, 0.5]], [0.5], np.diag([3.0, 1.0]), boundary=HardWalls(walls))
    r = verify(p)
    assert r.network.n_wall_contacts == 2
    assert r.local is False and r.local_rattler.all()
    assert r.collective is False and r.strict is False


def test_a_disk_filling_a_square_box_is_jammed_with_four_equal_wall_reactions():
    """One disk of diameter 1 in the unit square touches all four walls: dx >= 0 (wall x = 0),
    dx <= 0 (x = 1), likewise in y, so dr = 0: locally and collectively jammed; the walls are
    fixed, so strictly jammed too (the strict test is the collective one). Forces: balance
    gives f_left = f_right, f_bottom = f_top; the most uniform self-stress is all 1. Counting:
    N_f = N d = 2, M = 4 (hyperstatic by 1). Virial (sum of f times the centre-wall distance
    1/2 over the 4 contacts) = d P V with P V = 1 (force 1 on each unit wall): 2 = 2."""
    p = Packing([[0.5, 0.5]], [0.5], np.eye(2), boundary=HardWalls([0, 1]))
    r = verify(p)
    assert r.verdicts == {"local": True, "collective": True, "strict": True}
    assert r.strict_test.method == "walls fixed: the collective test"
    np.testing.assert_allclose(r.forces.forces, 1.0, rtol=1e-12)
    assert np.abs(r.forces.imbalance).max() < 1e-14
    assert r.statics.n_dof_collective == 2 and r.statics.isostaticity_gap == 1
    assert r.statics.n_wall_contacts == 4 and r.statics.wall_force == pytest.approx(4.0)
    assert r.statics.pressure_virial * 2 * r.volume == pytest.approx(2.0)


def test_a_disk_in_a_corner_is_a_rattler_and_two_disks_in_a_closed_slot_are_jammed():
    """Corner: one disk touching only the walls x = 0 and y = 0 of a 3 x 3 box: constraints
    dx >= 0, dy >= 0 leave it free to leave the corner (2 < d + 1 contacts): a rattler.

    Slot: two disks of diameter 1 at (0.5, 0.5) and (1.5, 0.5) in a box 2 x 1. Disk 1 has
    dx1 >= 0 (wall x = 0), disk 2 dx2 <= 0 (wall x = 2), the pair dx2 - dx1 >= 0, so
    0 <= dx1 <= dx2 <= 0; the walls y = 0, 1 give dy = 0: both stay put, collectively jammed.
    N_f = 4, M = 7 (6 wall contacts, 1 pair). Balance: the pair force equals both side-wall
    reactions and each disk's floor and ceiling reactions are equal; the most uniform
    self-stress is 1 on every contact."""
    corner = Packing([[0.5, 0.5]], [0.5], 3 * np.eye(2), boundary=HardWalls([0, 1]))
    assert verify(corner).local is False
    slot = Packing([[0.5, 0.5], [1.5, 0.5]], [0.5, 0.5], np.diag([2.0, 1.0]), boundary=HardWalls([0, 1]))
    r = verify(slot)
    assert r.verdicts == {"local": True, "collective": True, "strict": True}
    assert r.network.n_wall_contacts == 6 and r.statics.n_contacts == 7 and r.statics.n_dof_collective == 4
    np.testing.assert_allclose(r.forces.forces, 1.0, rtol=1e-9)


def test_a_chain_of_rods_between_two_walls_is_isostatic_and_jammed_in_one_dimension():
    """d = 1: three rods of length 1 filling [0, 3] between walls. Constraints dx1 >= 0,
    dx1 <= dx2 <= dx3, dx3 <= 0: all zero, so collectively jammed; M = 4 = N_f + 1 with
    N_f = N d = 3: isostatic, and force balance makes all four forces equal."""
    p = Packing([[0.5], [1.5], [2.5]], [0.5] * 3, [[3.0]], boundary=HardWalls([0]))
    r = verify(p)
    assert r.verdicts == {"local": True, "collective": True, "strict": True}
    assert r.statics.isostaticity_gap == 0 and r.statics.n_wall_contacts == 2
    np.testing.assert_allclose(r.forces.forces, 1.0, rtol=1e-12)


def test_a_chain_of_disks_between_two_walls_is_not_locally_jammed():
    """d = 2: three disks of diameter 1 along x between the walls x = 0 and x = 3, y periodic
    (height 3). Each disk has 2 contacts (< d + 1), with normals +-e_x: it slides along y, so
    every disk is a rattler."""
    p = Packing([[0.5, 1.5], [1.5, 1.5], [2.5, 1.5]], [0.5] * 3, np.diag([3.0, 3.0]), boundary=HardWalls([0]))
    r = verify(p)
    assert r.network.n_wall_contacts == 2 and r.network.n_contacts == 4
    assert r.local is False and r.local_rattler.all()


def test_a_sphere_in_a_container_touching_nothing_is_a_rattler():
    """A sphere of radius 1/2 at the centre of a spherical container of radius 2 has no contact:
    it moves freely, a rattler, and nothing is jammed."""
    p = Packing([[2.0, 2.0, 2.0]], [0.5], 4 * np.eye(3), boundary=SphericalContainer([2, 2, 2], 2.0))
    r = verify(p)
    assert r.network.n_contacts == 0
    assert r.local is False and r.local_rattler.all()
    assert r.collective is False and r.strict is False


def flower_in_container() -> Packing:
    """Seven disks of diameter 1: one at the centre of a circular container of radius 3/2, six
    around it at distance 1 (60 degrees apart), each touching the centre disk, its two
    neighbours and the container wall."""
    angles = np.arange(6) * np.pi / 3
    pos = np.vstack([[0.0, 0.0], np.column_stack([np.cos(angles), np.sin(angles)])]) + 2.0
    return Packing(pos, np.full(7, 0.5), 4 * np.eye(2), boundary=SphericalContainer([2.0, 2.0], 1.5))


def test_a_flower_in_a_circular_container_is_jammed_up_to_its_rotation():
    """The seven disks of :func:`flower_in_container`, e_k the radial unit vectors of the outer
    disks. Wall: v_k . e_k <= 0; centre contact: (v_k - v_0) . e_k >= 0. Summing over k,
    sum v_k . e_k >= v_0 . sum e_k = 0, so every v_k . e_k = 0 and v_0 . e_k <= 0 for six
    directions that positively span the plane: v_0 = 0. The outer disks then move tangentially,
    v_k = w_k t_k, and the ring contact k, k+1 reads (sqrt 3 / 2)(w_{k+1} - w_k) >= 0 around the
    ring: all w_k equal, a rigid rotation about the centre -- a trivial motion of a circular
    container. So the packing is collectively jammed (and, the container fixed, strictly), with
    N_f = 2 N - 1 = 13 (the rotation removed) and M = 18. Every outer disk's balance pushes it
    onto the wall (wall reaction = centre force + ring force > 0), and the virial over all
    contacts equals R times the total wall reaction (sum_i x_i . F_i = 0 with the origin at the
    centre): d P V = R sum f_wall."""
    r = verify(flower_in_container())
    assert r.verdicts == {"local": True, "collective": True, "strict": True}
    s = r.statics
    assert s.n_dof_collective == 13 and s.n_contacts == 18 and s.n_wall_contacts == 6
    wall = r.network.is_wall
    assert r.forces.forces[wall].min() > 0 and np.abs(r.forces.imbalance).max() < 1e-12
    assert s.pressure_virial * 2 * r.volume == pytest.approx(1.5 * s.wall_force, rel=1e-12)


def test_a_flower_missing_a_petal_unjams():
    """The flower without one outer disk. The outer disk next to the gap touches the centre disk,
    the container wall and one ring neighbour; the first two pin its centre to the circle of
    radius 1 about the container's centre (|x - c| >= 1 from the centre disk, <= R - r = 1 from
    the wall), along which it slides into the gap while every other disk stays put: it is not
    locally jammed (its three contact normals leave the tangent towards the gap free:
    Donev 2006, sec. 4.4.3.1). Removing it frees the next one, and so on round the chain; the
    centre disk is left alone: every disk is a rattler and nothing is jammed."""
    p = flower_in_container()
    p = p.replace(positions=p.positions[:-1], radii=p.radii[:-1])
    r = verify(p)
    assert r.local is False and r.local_rattler.all()
    assert r.collective is False


def test_wall_contacts_of_the_network():
    """Gap and normal of a wall contact (module docstring of hardpack.jamming.contacts): a disk
    of radius 1/2 at height 0.5 + 1e-7 over the floor of a 3 x 3 box."""
    p = Packing([[1.5, 0.5 + 1e-7]], [0.5], 3 * np.eye(2), boundary=HardWalls([0, 1]))
    net = contact_network(p, 1e-6)
    assert net.n_contacts == 1 and net.wall[0] == 2  # the wall y = 0 (axis 1, lower)
    np.testing.assert_allclose(net.normal[0], [0.0, -1.0])
    assert net.gap[0] == pytest.approx(1e-7, rel=1e-6)
    assert contact_network(p, 1e-8).n_contacts == 0


def test_cli_init_with_walls_and_verify_writes_wall_contacts(tmp_path):
    """``hardpack init --boundary`` starts walled packings (for ``hardpack compress``), and
    ``hardpack verify`` of a walled packing stores its wall contacts and reactions: the closed
    slot of two disks (7 contacts, 6 with walls, all forces 1) of the test above."""
    from hardpack.cli import main
    from hardpack.io import load_dataset, load_packing, save_packing

    assert main(["init", "--n", "5", "--d", "2", "--phi", "0.1", "--seed", "1", "--boundary",
                 "spherical_container", "--out", str(tmp_path / "init.nc")]) == 0
    assert load_packing(tmp_path / "init.nc").boundary.kind == "spherical_container"
    slot = Packing([[0.5, 0.5], [1.5, 0.5]], [0.5, 0.5], np.diag([2.0, 1.0]), boundary=HardWalls([0, 1]))
    save_packing(slot, tmp_path / "slot.nc")
    assert main(["verify", str(tmp_path / "slot.nc"), "--out", str(tmp_path / "v.nc")]) == 0
    ds = load_dataset(tmp_path / "v.nc")
    assert ds.attrs["collective"] == 1 and ds.attrs["n_wall_contacts"] == 6
    assert ds.attrs["wall_force"] == pytest.approx(6.0)
    np.testing.assert_allclose(ds["force"].values[ds["contact_wall"].values >= 0], 1.0, rtol=1e-9)
