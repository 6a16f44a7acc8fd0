"""Table 4.1 of Donev's dissertation and the strictly jammed 2D packings of Fig. 4.11.

Source: Donev 2006, dissertation sec. 4.7.1 (Table 4.1, periodic boundary conditions)
and sec. 4.7.1.1 (Fig. 4.11, Eq. 4.26). The text chose "the smallest unit cells for which an
unjamming motion exists", with N_s particles per cell. The cells used here are index-k
supercells of the primitive cell (matrix columns = new lattice vectors in primitive units): the
first doubling along the third (2D: second) primitive vector gives the N_s of the table and an
unjamming motion for every lattice marked C = N, while the primitive cells of those lattices
are collectively jammed (tested below), so the table's N_s is indeed the smallest.

Exact expectations: every verdict is a yes/no of an exact LP test on packings with exact
contacts (gaps ~1e-16), so no tolerance enters except delta = 1e-6, which only has to separate
exact contacts from the next neighbour shell (relative gap >= 0.15 in all these crystals).
"""

from __future__ import annotations

import numpy as np
import pytest
from test_jamming_support import (
    primitive_cell,
    reinforced_kagome,
    supercell,
    triangular_with_vacancies,
)

from hardpack.geometry.lattices import lattice_packing
from hardpack.jamming import rigidity_matrix, verify

D2, D3 = [[1, 0], [0, 2]], [[1, 0, 0], [0, 1, 0], [0, 0, 2]]
I2, I3 = np.eye(2, dtype=int), np.eye(3, dtype=int)

# name, cell matrix, printed phi, Z, printed N_s, L, C, S   (Donev 2006, Table 4.1)
TABLE_4_1 = [
    ("honeycomb", D2, 0.605, 3, 4, True, False, False),
    # printed Z = 6 for Kagome is a misprint: every Kagome disk touches 4 others (Donev 2006,
    # Table 4.1); we assert the true value.
    ("kagome", I2, 0.680, 4, 3, True, False, False),
    ("square", D2, 0.785, 4, 2, True, False, False),
    ("triangular", I2, 0.907, 6, 1, True, True, True),
    ("diamond", D3, 0.340, 4, 4, True, False, False),
    ("sc", D3, 0.524, 6, 2, True, False, False),
    ("bcc", D3, 0.680, 8, 2, True, False, False),
    ("fcc", I3, 0.741, 12, 1, True, True, True),
    ("hcp", I3, 0.741, 12, 2, True, True, True),
]


@pytest.mark.parametrize("name, cell, phi, z, ns, local, collective, strict", TABLE_4_1,
                         ids=[row[0] for row in TABLE_4_1])
def test_table_4_1(name, cell, phi, z, ns, local, collective, strict):
    p = supercell(primitive_cell(name), cell)
    assert p.n_particles == ns
    # printed to 3 decimals; FCC/HCP pi/sqrt(18) = 0.74048 is printed 0.741 (rounded up)
    assert abs(p.phi - phi) <= 6e-4
    r = verify(p, delta=1e-6, seed=1)
    assert r.network.n_contacts * 2 / p.n_particles == z
    assert (r.local, r.collective, r.strict) == (local, collective, strict)
    assert not r.rattler.any() if collective else True
    # Donev 2006, sec. 4.2.2: strict => collective => local, reflected in the category string
    expected = "strictly jammed" if strict else "collectively jammed" if collective else "locally jammed"
    assert r.category == expected


@pytest.mark.parametrize("name", ["square", "honeycomb", "diamond", "sc", "bcc"])
def test_table_cells_are_the_smallest_with_a_mechanism(name):
    """The primitive cell (half the table's N_s) has no collective unjamming motion."""
    p = primitive_cell(name)
    r = verify(p, delta=1e-6, tests=("collective",), seed=2)
    assert r.collective


@pytest.mark.parametrize("name, reps", [("triangular", (3, 4)), ("triangular", (5, 5)),
                                        ("fcc", (2, 2, 2)), ("hcp", (2, 2, 2))])
def test_dense_lattices_strictly_jammed_in_larger_cells(name, reps):
    """Triangular is strictly jammed for every N_c (Donev 2006, sec. 4.4.2.1); FCC and HCP too."""
    r = verify(lattice_packing(name, reps), delta=1e-6, seed=3)
    assert r.strict and r.collective and r.local
    assert r.unjamming("collective")["max"] == 0.0 and r.unjamming("strict")["max"] == 0.0


def test_six_sevenths_lattice_strictly_jammed():
    """Fig. 4.11 top: every 7th disk of the triangular lattice removed (sqrt7 x sqrt7 cell)."""
    p = supercell(primitive_cell("triangular"), [[1, 0], [2, 7]])
    six = p.replace(positions=p.positions[1:], radii=p.radii[1:])
    assert six.n_particles == 6 and six.phi == pytest.approx(np.pi / (2 * np.sqrt(3)) * 6 / 7)
    r = verify(six, delta=1e-6, seed=4)
    assert r.strict


@pytest.mark.parametrize("n", [3, 5, 7])
def test_reinforced_kagome_strictly_jammed(n):
    """Fig. 4.11 middle: Kagome plus one full row and column is strictly jammed, with density
    decreasing to the Kagome value sqrt(3) pi / 8 = 0.680 (Eq. 4.26 bound n <= N/4)."""
    p = reinforced_kagome(n)
    holes = ((n - 1) // 2) ** 2
    assert p.n_particles == n * n - holes
    r = verify(p, delta=1e-6, seed=5)
    assert r.strict


def test_kagome_pattern_without_reinforcement_unjams():
    """The same vacancy pattern in a 2 x 2 cell is the plain Kagome lattice: not collectively
    jammed, although it respects the counting bound of Eq. 4.26 (n = N/4)."""
    p = triangular_with_vacancies(2, [(0, 0)])
    r = verify(p, delta=1e-6, seed=6)
    assert r.local and not r.collective and not r.strict


def test_divacancy_unjams_triangular_lattice():
    """Donev 2006, sec. 4.7.1.1: a compact divacancy unjams the (strictly jammed) triangular packing."""
    p = triangular_with_vacancies(6, [(0, 0), (1, 0)])
    r = verify(p, delta=1e-6, seed=7)
    assert not r.strict


@pytest.mark.parametrize("name", ["square", "honeycomb", "kagome", "sc", "bcc", "diamond"])
def test_unjamming_motions_are_feasible(name):
    """The reported collective motion V obeys A^T V >= 0 (ideal contacts) and moves particles
    relative to each other by much more than dr_large; the strict motion has Tr eps <= 0."""
    cell = dict(TABLE_4_1_CELLS)[name]
    p = supercell(primitive_cell(name), cell)
    r = verify(p, delta=1e-6, seed=8)
    a = rigidity_matrix(r.network)
    v = r.collective_test.motion
    stretch = a.T @ v.ravel()
    assert stretch.min() > -1e-9
    assert np.linalg.norm(v, axis=1).max() > 1e3 * r.params["dr_large"]
    eps = r.strict_test.strain
    if eps is not None:
        assert np.trace(eps) < 1e-12


TABLE_4_1_CELLS = [(row[0], row[1]) for row in TABLE_4_1]
