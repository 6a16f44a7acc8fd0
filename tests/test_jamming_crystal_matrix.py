"""Crystals in supercells, rebased and rotated cells, with both jamming tests (Donev 2006, ch. 4).

The matrix: the lattices of Donev 2006, Table 4.1 (honeycomb, Kagome, square, triangular,
diamond, SC, BCC, FCC, HCP; the cells of ``lattice_packing``: primitive for the 2D lattices,
SC and HCP, conventional cubic for BCC, FCC and diamond) and the FCC primitive cell, in every
supercell of 1-3 cells per lattice vector, plus the same periodic packings described by another
basis of the same lattice (a unimodular integer change of the lattice vectors) and rigidly
rotated. Each is verified with Algorithm 13 ("ideal") and Algorithm 14 ("sequential"): no
crash, no BLAS error message, and the verdict that theory dictates, the same for both methods
and for every description of the same packing.

Expected verdicts (derived here, not taken from our output). Every one of these crystals has a
strictly positive self-stress (equal forces on all contacts: each particle's contact normals sum
to zero) whose stress is isotropic (cubic or hexagonal symmetry; for HCP with ideal c/a the 12
unit normals give sum u u^T = 4 I as in FCC), i.e. a pressure. Then any first-order motion
(A^T dQ >= 0, Tr eps <= 0) has A^T dQ = 0 and Tr eps = 0 (multiply by the forces), and for
spheres such a first-order flex is an unjamming motion (Donev sec. 4.3, "rigid iff
infinitesimally rigid"; with strain sec. 4.4.4: Tr eps = 0 decreases the volume at second
order). So the collective test asks whether the bar framework of the contacts has an
infinitesimal mechanism periodic in the cell, the strict test whether it has one with a
traceless strain. A motion periodic in a cell is a sum of Bloch waves exp(i q.R) with q in the
cell's reciprocal lattice; q = 0 (modulo the primitive reciprocal lattice) is the only wave of a
primitive cell, and the strain couples to q = 0 only (Donev 2006: the strain is the same for
every supercell, secs. 4.4.5.4-4.4.6; any motion of a cell is one of its supercells, sec. 4.4.6.3).

- Bravais lattices (one particle per primitive cell; neighbour vectors r): a wave q != 0 is a
  mechanism iff a displacement v is perpendicular to every r with q.r not in 2 pi Z.
  * triangular: any two of its three directions generate the lattice, so q != 0 leaves two of
    them out of phase and no v is perpendicular to both; strain: u^T eps u = 0 on three
    directions 60 degrees apart forces eps = 0. Strictly jammed in every cell (Donev 2006, sec. 4.4.2.1).
  * FCC (conventional and primitive cells): of the six directions <110>, any three
    independent ones generate the lattice, and at most three lie in a plane (the {111}), so
    q != 0 leaves a spanning set out of phase; strain: u^T eps u = 0 on the six <110> gives
    eps_pq = 0 and eps_pp + eps_qq = 0 for all p != q, so eps = 0. Strictly jammed in every cell.
  * square, SC: with q = 2 pi (m_1/k_1, ...) (cell of k_p primitive cells along e_p) the
    directions e_p with m_p = 0 are in phase; m = (0, .., 1, .., 0), possible iff some k_p >= 2,
    leaves one direction: rows (square) or lines (SC) slide along themselves. Collectively
    jammed iff every k_p = 1 (one particle: no relative motion at all). Strain: the shear
    eps_pq (p != q) keeps every contact (u = e_p) at first order: never strictly jammed (Donev
    Table 4.1: S = N).
  * BCC in its conventional cubic cell (k_1, k_2, k_3): the four body diagonals; any three
    generate the lattice, so a mechanism needs exactly two in phase, which works out to
    m_p/k_p + m_q/k_q in Z with m_q/k_q not in Z for a pair p != q: possible iff
    gcd(k_p, k_q) >= 2 -- the {110} planes sliding along <1-10>, which touch their neighbour
    planes only along the two diagonals perpendicular to the slide. Collectively jammed iff
    the k_p are pairwise coprime, e.g. (1, 1, 1) (each particle caged by the eight images of
    the other), (2, 1, 1) or (3, 2, 1), but not (2, 2, 1) or (3, 3, 3). Strain: diag(s, -s, 0)
    keeps all eight diagonals at first order (the Bain deformation): never strictly jammed.
- Non-Bravais lattices, by counting per primitive cell at a wave q (bonds against degrees of
  freedom):
  * honeycomb (2 particles, 3 bonds, 4 dof): a mechanism at every q != 0; at q = 0 the
    relative displacement is perpendicular to three directions 120 degrees apart: only
    translations. ``lattice_packing``'s honeycomb cell is primitive, so collectively jammed
    only for (1, 1) (Table 4.1: N_s = 4 is the smallest cell that unjams). Strain: 2
    internal + 2 traceless strain components against 3 bonds leave a null flex in the
    primitive cell (Donev Fig. 4.10), hence in every cell: never strictly jammed.
  * Kagome (3 particles): the twisting triangles are a mechanism at q = 0 (Donev Figs. 4.6,
    4.9; Table 4.1 N_s = 3, the primitive cell): never collectively jammed.
  * diamond (2 particles, 4 bonds, 6 dof): at least two mechanisms at every q != 0; the
    conventional cubic cell holds four primitive cells, so q != 0 is allowed in all of
    ``lattice_packing``'s diamond cells: never collectively jammed (its primitive 2-particle
    cell is, see test_jamming_lattices.py).
  * HCP (2 particles, 12 bonds, 6 dof): strictly jammed (Table 4.1), in every cell: each
    close-packed layer nests in the hollows of the next, no stacking shift or strain keeps
    the three contacts to the layer below at first order.
- Local jamming holds everywhere: every particle's contact normals positively span R^d
  (opposite pairs; three at 120 degrees in the honeycomb; the tetrahedron in diamond), also
  when the neighbours are its own images.

:func:`framework_verdict` checks these rules independently of the verifier: the null spaces of
the contact framework's compatibility matrix (with and without the traceless strain), computed
by a dense SVD from the lattice geometry alone, after checking the premises (uniform
self-stress, isotropic stress).
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from test_jamming_support import primitive_cell, supercell

from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.jamming import verify

DIM = {"square": 2, "triangular": 2, "honeycomb": 2, "kagome": 2,
       "sc": 3, "bcc": 3, "fcc": 3, "fcc-primitive": 3, "hcp": 3, "diamond": 3}
LATTICES = tuple(DIM)
METHODS = ("ideal", "sequential")


def expected_verdict(name: str, reps: tuple) -> tuple[bool, bool]:
    """(collectively jammed, strictly jammed) of ``crystal(name, reps)``: the rules of the module
    docstring (locally jammed always)."""
    if name in ("triangular", "fcc", "fcc-primitive", "hcp"):
        return True, True
    if name in ("square", "sc"):
        return all(k == 1 for k in reps), False
    if name == "bcc":
        return all(math.gcd(a, b) == 1 for a, b in itertools.combinations(reps, 2)), False
    if name == "honeycomb":
        return tuple(reps) == (1, 1), False
    if name in ("kagome", "diamond"):
        return False, False
    raise ValueError(name)


def expected_category(name: str, reps: tuple) -> str:
    collective, strict = expected_verdict(name, reps)
    return "strictly jammed" if strict else "collectively jammed" if collective else "locally jammed"


def crystal(name: str, reps: tuple) -> Packing:
    """The crystal ``name`` with ``reps`` cells along each lattice vector of its cell."""
    if name == "fcc-primitive":
        return supercell(primitive_cell("fcc"), np.diag(reps))
    return lattice_packing(name, reps)


def rebased(packing: Packing, unimodular) -> Packing:
    """The same periodic packing with the lattice vectors lattice @ U (U integer, det U = +-1)."""
    u = np.asarray(unimodular, dtype=int)
    assert round(abs(np.linalg.det(u))) == 1
    return Packing(packing.positions, packing.radii, packing.lattice @ u)


def rotated(packing: Packing, angles) -> Packing:
    """The packing rigidly rotated (2D: by angles[0]; 3D: z-y-z Euler angles)."""
    rot = _rotation(packing.dim, angles)
    return Packing(packing.positions @ rot.T, packing.radii, rot @ packing.lattice)


def _rotation(d: int, angles) -> np.ndarray:
    def planar(a, p, q):
        r = np.eye(d)
        r[p, p] = r[q, q] = np.cos(a)
        r[p, q], r[q, p] = -np.sin(a), np.sin(a)
        return r

    if d == 2:
        return planar(angles[0], 0, 1)
    return planar(angles[0], 0, 1) @ planar(angles[1], 0, 2) @ planar(angles[2], 0, 1)


# ---------------------------------------------------------------- independent oracle
def _contacts(packing: Packing):
    """Every contact (i, j, lattice n, r_ij) once (|x_j + lattice n - x_i| = 1 to 1e-9), from
    the geometry alone: for each pair the images around the nearest one, up to 1 / height + 1/2
    cells away along each lattice vector (|r| <= 1 needs that)."""
    lat, n = packing.lattice, packing.n_particles
    frac = packing.fractional()
    i, j = np.triu_indices(n)  # i <= j
    nearest = -np.rint(frac[j] - frac[i])  # frac_j - frac_i + nearest in [-1/2, 1/2]
    reach = [range(-k, k + 1) for k in np.ceil(1.0 / packing.heights + 0.5).astype(int)]
    out = []
    for shift in itertools.product(*reach):
        image = nearest + np.array(shift)
        first = np.where(image != 0, image, 0)[np.arange(i.size), np.argmax(image != 0, axis=1)]
        keep = (i < j) | (first > 0)  # a self-image contact once, from its positive image
        r = (frac[j] - frac[i] + image) @ lat.T
        hit = keep & (np.abs(np.linalg.norm(r, axis=1) - 1.0) < 1e-9)
        out.extend(zip(i[hit], j[hit], image[hit] @ lat.T, r[hit]))
    return out


def framework_verdict(packing: Packing) -> tuple[bool, bool]:
    """(collectively, strictly) jammed from the contact framework by linear algebra (module
    docstring): mechanisms = null vectors of the compatibility matrix beyond the d translations,
    with the strain components added under Tr eps = 0 for the strict test."""
    n, d = packing.n_particles, packing.dim
    pairs = [(p, q) for p in range(d) for q in range(p, d)]
    rows, strain_rows = [], []
    for i, j, w, r in _contacts(packing):
        u = r / np.linalg.norm(r)
        row = np.zeros(n * d)
        row[j * d:(j + 1) * d] += u
        row[i * d:(i + 1) * d] -= u
        rows.append(row)
        strain_rows.append([u[p] * w[p] if p == q else u[p] * w[q] + u[q] * w[p] for p, q in pairs])
    a, s = np.array(rows), np.array(strain_rows)
    # premises: equal forces balance every particle and give an isotropic stress (a pressure)
    assert np.abs(a.sum(axis=0)).max() < 1e-9
    stress = s.sum(axis=0)
    diagonal = np.array([p == q for p, q in pairs])
    assert stress[diagonal].min() > 0 and np.ptp(stress[diagonal]) < 1e-9 and np.abs(stress[~diagonal]).max() < 1e-9

    def nullity(m):
        sv = np.linalg.svd(m, compute_uv=False)
        return m.shape[1] - int((sv > 1e-8 * sv.max()).sum())

    collective = nullity(a) == d
    trace = np.concatenate([np.zeros(n * d), diagonal.astype(float)])
    strict = nullity(np.vstack([np.hstack([a, s]), trace])) == d
    return collective, collective and strict


# ---------------------------------------------------------------- the matrix
def _grid(d):
    return list(itertools.product((1, 2, 3), repeat=d))


ALL_CELLS = [(name, reps) for name in LATTICES for reps in _grid(DIM[name])]
#: the default run: every lattice in its own cell, elongated and unequal supercells; the rest
#: of the 1-3 grid is marked slow
FAST_REPS = {2: [(1, 1), (2, 1), (1, 2), (2, 2), (3, 2)], 3: [(1, 1, 1), (2, 1, 1), (2, 2, 1), (3, 2, 1), (2, 2, 2)]}
FAST_CELLS = [(name, reps) for name in LATTICES for reps in FAST_REPS[DIM[name]]
              if not (name == "diamond" and reps == (2, 2, 2))]
SLOW_CELLS = [cell for cell in ALL_CELLS if cell not in FAST_CELLS]

#: another basis of the same lattice (unimodular) and a rotation, per dimension
UNIMODULAR = {2: [[2, 1], [1, 1]], 3: [[2, 1, 0], [1, 1, 0], [0, 1, 1]]}
SHEAR = {2: [[1, 0], [-2, 1]], 3: [[1, 0, 1], [1, 1, 0], [0, 0, 1]]}
ANGLES = {2: (0.7,), 3: (0.3, 1.1, -0.4)}


def _ids(cells):
    return [f"{name}-{'x'.join(map(str, reps))}" for name, reps in cells]


def _cells(fast, slow):
    """pytest parameters: the fast cells, then the slow ones marked slow."""
    return ([pytest.param(*cell, id=_ids([cell])[0]) for cell in fast]
            + [pytest.param(*cell, id=_ids([cell])[0], marks=pytest.mark.slow) for cell in slow])


@pytest.mark.parametrize("name, reps", _cells(FAST_CELLS, SLOW_CELLS))
def test_theory_table_matches_the_framework_null_spaces(name, reps):
    """The hand-derived rules (module docstring) against the exact linear algebra of the
    contact framework, for every cell of the matrix (no jamming code involved)."""
    assert framework_verdict(crystal(name, reps)) == expected_verdict(name, reps)


def _check(packing, name, reps, method):
    r = verify(packing, method=method, seed=3)
    assert r.local, (name, reps, method)
    assert r.category == expected_category(name, reps), (name, reps, method, r.summary())
    assert not r.undetermined
    if r.collective:
        assert not r.rattler.any()
    return r


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name, reps", _cells(FAST_CELLS, SLOW_CELLS))
def test_crystal_supercells(name, reps, method, capfd):
    _check(crystal(name, reps), name, reps, method)
    out, err = capfd.readouterr()
    assert "illegal value" not in out + err  # no BLAS call with a bad argument (SuperLU)


REBASED = [(name, reps) for name in LATTICES
           for reps in ([(1, 1), (3, 2)] if DIM[name] == 2 else [(1, 1, 1), (2, 1, 1)])]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name, reps", REBASED, ids=_ids(REBASED))
def test_rebased_and_rotated_cells(name, reps, method):
    """The same periodic packing described by a sheared basis (two unimodular changes of the
    lattice vectors) and rigidly rotated: the verdict of the plain cell."""
    d = DIM[name]
    plain = crystal(name, reps)
    for packing in (rebased(plain, UNIMODULAR[d]), rotated(rebased(plain, SHEAR[d]), ANGLES[d])):
        _check(packing, name, reps, method)


def test_rebased_cell_is_the_same_packing():
    """The helpers keep the packing: same density, same contacts per particle."""
    p = crystal("hcp", (2, 1, 1))
    for q in (rebased(p, UNIMODULAR[3]), rotated(rebased(p, SHEAR[3]), ANGLES[3])):
        assert q.phi == pytest.approx(p.phi, rel=1e-12)
        assert len(_contacts(q)) == len(_contacts(p)) == 6 * p.n_particles


# ---------------------------------------------------------------- property-based
@st.composite
def described_crystals(draw, max_reps: int, max_particles: int):
    """(name, reps, another description of the same packing): a lattice of the matrix in a
    supercell, its basis changed by a product of integer shears (and a quarter turn of two
    vectors), the whole rigidly rotated."""
    name = draw(st.sampled_from(LATTICES))
    d = DIM[name]
    reps = tuple(draw(st.lists(st.integers(1, max_reps), min_size=d, max_size=d)))
    plain = crystal(name, reps)
    assume(plain.n_particles <= max_particles)
    u = np.eye(d, dtype=int)
    for p, q, k in draw(st.lists(st.tuples(st.integers(0, d - 1), st.integers(0, d - 1),
                                           st.integers(-2, 2)), max_size=3)):
        if p != q:
            shear = np.eye(d, dtype=int)
            shear[p, q] = k
            u = u @ shear
    if draw(st.booleans()):  # (a_0, a_1) -> (a_1, -a_0): det +1
        turn = np.eye(d, dtype=int)
        turn[:2, :2] = [[0, -1], [1, 0]]
        u = u @ turn
    angles = draw(st.lists(st.floats(0.0, 2 * np.pi), min_size=1 if d == 2 else 3,
                           max_size=1 if d == 2 else 3))
    return name, reps, rotated(rebased(plain, u), angles)


@functools.lru_cache(maxsize=None)
def _plain_category(name, reps, method):
    """The verdict of the plain cell (deterministic: one verification per case and method)."""
    return verify(crystal(name, reps), method=method, seed=5).category


def _same_verdict(name, reps, other, method):
    described = verify(other, method=method, seed=5)
    assert described.category == _plain_category(name, reps, method) == expected_category(name, reps), (
        name, reps, method, other.lattice, described.summary())


@settings(max_examples=30, deadline=None, derandomize=True, database=None)
@given(described_crystals(max_reps=2, max_particles=32), st.sampled_from(METHODS))
def test_verdict_does_not_depend_on_the_description_of_the_packing(crystal_case, method):
    """Never a crash, and the verdict of the plain cell (the theory's) for any basis of the same
    lattice and any rotation."""
    name, reps, other = crystal_case
    _same_verdict(name, reps, other, method)


@pytest.mark.slow
@settings(max_examples=150, deadline=None, database=None)
@given(described_crystals(max_reps=3, max_particles=108), st.sampled_from(METHODS))
def test_verdict_does_not_depend_on_the_description_of_the_packing_many(crystal_case, method):
    name, reps, other = crystal_case
    _same_verdict(name, reps, other, method)
