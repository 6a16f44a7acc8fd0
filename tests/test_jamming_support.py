"""Test support for the jamming tests: unit cells of Table 4.1 and a small jammed-packing maker.

Not a packing generator of the library (those live in hardpack.md / hardpack.slp): this file only
makes small, exactly jammed disordered packings so that the jamming verifier can be tested
without the MD engine. Recipe (O'Hern et al. 2003 style, then made exact):

1. RSA (hardpack.initial.random_packing), radii inflated to a volume fraction above jamming;
2. harmonic soft-sphere energy minimisation (scipy L-BFGS) and bisection in phi down to the
   jamming threshold (relative overlaps ~1e-7);
3. the overlapping pairs of the last jammed state, rattlers (fewer than d + 1 contacts) removed
   iteratively, give an isostatic contact network; Gauss-Newton then solves |r_ij| = s D_ij on
   that network for the positions and one common diameter scale s, which makes every contact
   exact (gap ~1e-15) and every other pair open. Rattlers keep their place and shrink if needed.

The tests at the bottom check that the maker does what it says (exact contacts, isostatic).
The jamming tests read its 64 disks from tests/data (:func:`jammed_disks`); a slow test checks
that the maker still makes them.
"""

from __future__ import annotations

import functools
import itertools
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import minimize
from scipy.spatial import cKDTree

from hardpack.distributions import bidisperse
from hardpack.geometry.neighbours import pairs_within
from hardpack.geometry.packing import Packing
from hardpack.initial import random_packing
from hardpack.io import load_packing

S3 = np.sqrt(3.0)


# ---------------------------------------------------------------------------- unit cells
def primitive_cell(name: str) -> Packing:
    """Primitive cells (NN distance 1, radius 1/2) for the lattices of Table 4.1."""
    from hardpack.geometry.lattices import lattice_packing

    if name == "bcc":
        a = 2 / S3
        lat = a / 2 * np.array([[-1, 1, 1], [1, -1, 1], [1, 1, -1]], float).T
        return Packing(np.zeros((1, 3)), [0.5], lat)
    if name in ("fcc", "diamond"):
        a = np.sqrt(2.0) if name == "fcc" else 4 / S3
        lat = a / 2 * np.array([[0, 1, 1], [1, 0, 1], [1, 1, 0]], float).T
        pos = np.zeros((1, 3)) if name == "fcc" else np.array([[0, 0, 0], [a / 4] * 3])
        return Packing(pos, [0.5] * len(pos), lat)
    return lattice_packing(name, 1)  # square, triangular, honeycomb, kagome, sc, hcp: primitive


def supercell(packing: Packing, matrix) -> Packing:
    """The same crystal in the cell lattice @ matrix (integer matrix, columns = new vectors)."""
    s_mat = np.asarray(matrix, dtype=int)
    d = packing.dim
    k = round(abs(np.linalg.det(s_mat)))
    inv = np.linalg.inv(s_mat)
    reach = int(np.abs(s_mat).sum()) + 1
    frac = []
    for m in itertools.product(range(-reach, reach + 1), repeat=d):
        f = (packing.fractional() + np.array(m)) @ inv.T
        frac.append(f - np.floor(f + 1e-9))
    frac = np.concatenate(frac)
    _, first = np.unique(np.round(frac * 1e6).astype(np.int64) % 1_000_000, axis=0, return_index=True)
    frac = frac[np.sort(first)]
    assert len(frac) == k * packing.n_particles
    lat = packing.lattice @ s_mat
    radii = np.resize(packing.radii, len(frac))
    return Packing(frac @ lat.T, radii, lat)


def remove_sites(packing: Packing, drop) -> Packing:
    keep = np.ones(packing.n_particles, dtype=bool)
    keep[np.asarray(drop)] = False
    return Packing(packing.positions[keep], packing.radii[keep], packing.lattice)


def triangular_with_vacancies(n: int, vacancies) -> Packing:
    """n x n triangular cell with the sites (a, b) in ``vacancies`` removed."""
    from hardpack.geometry.lattices import lattice_packing

    p = lattice_packing("triangular", (n, n))
    ab = np.round(p.fractional() * n).astype(int) % n
    drop = [k for k, (a, b) in enumerate(ab) if (a, b) in set(vacancies)]
    return remove_sites(p, drop)


def reinforced_kagome(n: int) -> Packing:
    """Kagome pattern (every 4th site of the triangular lattice removed) in an n x n cell with n
    odd, so one extra row and column of disks stays full (Donev Fig. 4.11)."""
    holes = [(a, b) for a in range(0, n - 1, 2) for b in range(0, n - 1, 2)]
    return triangular_with_vacancies(n, holes)


# ---------------------------------------------------------------------------- jammed maker
def _energy(flat, radii, box):
    """Harmonic overlap energy sum (1 - r/D)^2 / 2 and its gradient in a cubic periodic box."""
    n, d = len(radii), len(box)
    x = flat.reshape(n, d) % box
    x[x >= box] = 0.0
    tree = cKDTree(x, boxsize=box)
    ij = tree.query_pairs(2.0 * radii.max(), output_type="ndarray")
    sep = x[ij[:, 1]] - x[ij[:, 0]]
    sep -= box * np.round(sep / box)
    dist = np.linalg.norm(sep, axis=1)
    contact = radii[ij[:, 0]] + radii[ij[:, 1]]
    over = np.maximum(1.0 - dist / contact, 0.0)
    coef = (over / contact / dist)[:, None] * sep
    grad = np.zeros((n, d))
    np.add.at(grad, ij[:, 0], coef)
    np.add.at(grad, ij[:, 1], -coef)
    return 0.5 * float(over @ over), grad.ravel()


def _relax(x, radii, box):
    res = minimize(_energy, x.ravel(), args=(radii, box), jac=True, method="L-BFGS-B",
                   options={"maxiter": 20_000, "ftol": 1e-30, "gtol": 1e-14, "maxcor": 20})
    return res.x.reshape(x.shape) % box, res.fun


def soft_jammed(n: int, d: int, distribution, seed: int, phi_high: float) -> Packing:
    """An exactly jammed, isostatic packing (see the module docstring)."""
    start = random_packing(n, d, distribution, 0.3 if d == 3 else 0.5, seed=seed)
    lattice, base = start.lattice, start.radii
    vol_frac = start.phi

    def radii_at(phi):
        return base * (phi / vol_frac) ** (1.0 / d)

    box = np.diag(lattice).copy()
    x_hi, e_hi = _relax(start.positions, radii_at(phi_high), box)
    assert e_hi > 1e-12 * n, "phi_high is not above jamming"
    lo, hi = vol_frac, phi_high
    while True:
        mid = 0.5 * (lo + hi)
        x_mid, e_mid = _relax(x_hi, radii_at(mid), box)
        if e_mid > 1e-22 * n:
            hi, x_hi = mid, x_mid
        else:
            lo = mid
        if (hi - lo) / hi < 1e-5:
            made = _exact_contacts(x_hi, radii_at(hi), lattice)
            if made is not None:
                return made
        assert (hi - lo) / hi > 1e-9, "no isostatic jammed network found"


def _exact_contacts(x, radii, lattice):
    """Gauss-Newton onto |r_ij| = s D_ij for the rattler-free overlap network, if it is isostatic."""
    n, d = radii.size, lattice.shape[0]
    p = Packing(x, radii, lattice, allow_overlap=True)
    pr = pairs_within(p, rel_gap=0.0)
    active = np.ones(n, dtype=bool)
    while True:  # rattlers: fewer than d + 1 overlapping neighbours, iteratively
        keep = active[pr.i] & active[pr.j]
        count = np.bincount(pr.i[keep], minlength=n) + np.bincount(pr.j[keep], minlength=n)
        few = active & (count < d + 1)
        if not few.any():
            break
        active &= ~few
    keep = active[pr.i] & active[pr.j]
    if keep.sum() != d * (active.sum() - 1) + 1:
        return None
    ci, cj, shift, dij = pr.i[keep], pr.j[keep], pr.shift[keep], pr.contact[keep]
    x = p.fractional() @ lattice.T  # the wrapped centres the pair shifts refer to
    scale = 1.0
    for _ in range(30):  # Gauss-Newton on |x_j + L n - x_i| = scale D_ij
        sep = x[cj] + shift @ lattice.T - x[ci]
        dist = np.linalg.norm(sep, axis=1)
        resid = dist - scale * dij
        if np.abs(resid).max() < 1e-14:
            break
        u = sep / dist[:, None]
        m = len(ci)
        rows = np.repeat(np.arange(m), 2 * d)
        cols = np.concatenate([ci[:, None] * d + np.arange(d), cj[:, None] * d + np.arange(d)], 1).ravel()
        jac = sp.csr_matrix((np.concatenate([-u, u], 1).ravel(), (rows, cols)), shape=(m, n * d))
        jac = sp.hstack([jac, sp.csr_matrix(-dij[:, None])], format="csr")
        step = spla.lsqr(jac, -resid, atol=1e-16, btol=1e-16, iter_lim=20 * n * d)[0]
        x += step[:-1].reshape(n, d)
        scale += step[-1]
    else:
        return None
    radii = radii * scale
    # rattlers keep their place; shrink one if a neighbour moved into it
    for k in np.flatnonzero(~active):
        q = Packing(x, radii, lattice, allow_overlap=True)
        near = pairs_within(q, rel_gap=0.01)
        mine = (near.i == k) | (near.j == k)
        if mine.any():
            other = np.where(near.i[mine] == k, near.j[mine], near.i[mine])
            room = (near.distance[mine] - radii[other]).min()
            radii[k] = min(radii[k], room * (1 - 1e-6))
    return Packing(x, radii, lattice)


#: jammed_disks() as stored: making them takes 25 CPU s (the bisection of soft-sphere
#: minimisations), which every test run paid; test_maker_still_makes_the_stored_disks (slow)
#: checks that the maker gives them
JAMMED_DISKS = Path(__file__).parent / "data" / "jammed_disks_n64.nc"


def make_jammed_disks() -> Packing:
    """64 binary disks (size ratio 1.4, equimolar), exactly jammed."""
    return soft_jammed(64, 2, bidisperse(1.4, 0.5), seed=3, phi_high=0.87)


@functools.cache
def jammed_disks() -> Packing:
    """:func:`make_jammed_disks`'s packing, read from ``tests/data`` (JAMMED_DISKS)."""
    return load_packing(JAMMED_DISKS)


# ---------------------------------------------------------------------------- self-tests
def _check_exact_isostatic_contacts(p: Packing) -> None:
    gaps = np.sort(pairs_within(p, rel_gap=0.05).gap)
    tight = gaps[gaps < 1e-12]
    assert tight.size == 2 * (p.n_particles - 2 - 1) + 1  # isostatic: 2 rattlers for seed 3
    assert gaps[tight.size] > 1e-5
    assert np.abs(tight).max() < 1e-12


def test_maker_gives_exact_isostatic_contacts():
    """The backbone contacts are exact to round-off and the next pair is open by more than
    1e-5, so any contact tolerance between 1e-12 and 1e-5 sees the same network (what the
    jamming tests rely on)."""
    _check_exact_isostatic_contacts(jammed_disks())


@pytest.mark.slow
def test_maker_still_makes_the_stored_disks():
    """The maker's packing is the stored one and exactly isostatic itself: same cell and radii,
    the same contact network, and the backbone at the same positions up to a rigid translation
    (a zero mode of every periodic packing) to round-off. The minimisations' last bits differ
    between hosts, which moves the whole packing (seen: 6e-6 of a side on another CPU) and the
    two rattlers within their cages, so neither is compared."""
    made = make_jammed_disks()
    _check_exact_isostatic_contacts(made)
    stored = jammed_disks()
    np.testing.assert_allclose(made.lattice, stored.lattice, rtol=1e-12)
    np.testing.assert_allclose(made.radii, stored.radii, rtol=1e-12)

    def network(p):
        near = pairs_within(p, rel_gap=0.05)
        tight = near.gap < 1e-12
        return set(zip(near.i[tight].tolist(), near.j[tight].tolist()))

    contacts = network(made)
    assert contacts == network(stored)
    backbone = np.unique(np.array(sorted(contacts)))
    assert backbone.size == made.n_particles - 2  # the two rattlers of seed 3
    side = made.lattice[0, 0]
    shift = made.positions[backbone] - stored.positions[backbone]
    shift -= side * np.round(shift / side)
    np.testing.assert_allclose(shift, np.broadcast_to(shift.mean(axis=0), shift.shape), rtol=0, atol=1e-12 * side)
