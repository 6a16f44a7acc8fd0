"""Disordered packings from the LS engine (hardpack.md): jamming, contact number, forces.

Published targets (Donev 2006, dissertation chs. 4-5): LS packings of
monodisperse spheres (phi ~ 0.64) and equimolar binary disks (size ratio 1.4, phi ~ 0.84) are
collectively jammed but, from a fixed cell, not strictly jammed (secs. 4.7.2.1 and 4.6.2.5), with
Z = 2d after rattler removal for generic (isostatic) packings (sec. 4.7.2.1; Eq. 5.1)
and rattler fractions up to ~2.5 % in 3D and ~5 % in 2D (sec. 5.2). The free-volume
pressure p = d / (1 - phi/phi_J) (Eq. 5.24, "verified numerically for disordered isostatic hard
sphere packings") ties the jamming gap of the force network to the MD pressure.

Protocol (:func:`make_ls_packing`): 250 particles, RSA, LS growth at Gamma = 1e-2 to a reduced
pressure of 1e3, then Gamma = 1e-4 to 1e12 (hardpack.md.compress). The two packings (86 million
collisions for the spheres, about 90 s of LS) are stored in tests/data with their MD pressure
and the call that made them: these tests check the verifier on LS packings, and the LS engine's
own packings are checked by tests/test_md_protocol.py, tests/test_jamming_md_forces.py and the
smoke DAG's jamming rows. Faster final rates leave larger packings incompletely jammed (at
N = 500-1000 and Gamma = 3e-4 the delta = 1e-6 network is 2 contacts short of isostatic), as
Donev's Table 4.5 shows for few collisions per particle. At N = 250 the 3D rattler fraction
scatters by about +-1 % between seeds (1.2-3.2 % seen). Tolerance delta = 1e-6: contact gaps are
~1e-12 at that pressure, the next neighbours ~1e-5 and beyond.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hardpack import md
from hardpack.initial import random_packing
from hardpack.io import dataset_to_packing, load_dataset
from hardpack.jamming import verify

DATA = Path(__file__).parent / "data"


def make_ls_packing(n, d, distribution, seed):
    """The protocol of the module docstring: (packing, reduced MD pressure). It wrote the stored
    packings (their ``protocol`` attribute names the call), with ``md_pressure`` the second value."""
    start = random_packing(n, d, distribution, 0.3 if d == 3 else 0.5, seed=seed)
    fast = md.compress(start, 1e-2, seed, md.StopCriteria(max_pressure=1e3))
    slow = md.compress(fast.packing, 1e-4, seed + 1, md.StopCriteria(max_pressure=1e12))
    return slow.packing, slow.stats["Z"]  # hardpack.md calls the reduced pressure Z


def _stored(name):
    ds = load_dataset(DATA / f"{name}.nc")
    assert "make_ls_packing(250" in ds.attrs["protocol"]
    return dataset_to_packing(ds), float(ds.attrs["md_pressure"])


@pytest.fixture(scope="module")
def spheres():
    return _stored("ls_spheres_n250_seed1_p1e12")


@pytest.fixture(scope="module")
def disks():
    return _stored("ls_binary_disks_n250_seed1_p1e12")


def _common_checks(r, d):
    assert r.collective and not r.strict
    s, f = r.statics, r.forces
    assert abs(s.isostaticity_gap) <= 2
    assert r.z_mean == pytest.approx(2 * d, abs=0.05)
    loaded = f.forces[r.network.among(~r.rattler)]
    assert loaded.min() >= 0 and np.abs(f.imbalance).max() < 1e-12 * loaded.max()
    # fixed-cell LS packings unjam by a strain that keeps Tr eps <= 0
    assert np.trace(r.strict_test.strain) <= 1e-12 and r.unjamming("strict")["strain"] > 0
    # free-volume law (Donev 2006, Eq. 5.24): p (1 - phi / phi_J) -> d for isostatic sphere
    # packings, "verified numerically"; with phi_J from the forces and gaps of the nearest jamming
    # point, C = d x (free-volume pressure / MD pressure) must round to the printed integer d
    assert abs(d * r.pressure_ratio - d) < 0.5


def test_ls_spheres(spheres):
    packing, pressure = spheres
    r = verify(packing, delta=1e-6, seed=0, md_pressure=pressure)
    _common_checks(r, 3)
    # Donev: up to ~2.5 % in 3D (Donev 2006, sec. 5.2). One N = 250 sample scatters by about +-1.2 % (binomial;
    # we measured 1.2-4.4 % over 7 LS packings, mean 2.4 %, and 1.7 % at N = 1000), so a single
    # sample is held to 5 % (2 sigma above 2.5 %)
    assert r.rattler_fraction <= 0.05
    assert 0.63 < packing.phi < 0.66


def test_ls_binary_disks(disks):
    packing, pressure = disks
    r = verify(packing, delta=1e-6, seed=0, md_pressure=pressure)
    _common_checks(r, 2)
    # Donev: "as many as 5 %" in 2D (sec. 5.2); our LS disks at N = 250 have 5-7 % (seeds 1-2)
    assert r.rattler_fraction <= 0.08
    assert 0.83 < packing.phi < 0.86


def test_sequential_loading_of_ls_spheres(spheres):
    """Algorithm 14 (Tables 4.5-4.6, N = 250-1000 at 10^4-2.5 10^4 collisions per particle:
    collective <D r> / D = 3e-4 - 3e-3, strict 2e-3 - 1e-2): the collective displacements of a
    converged LS packing are below 1e-3 D, the strict ones (cell deformation allowed) larger."""
    packing, _ = spheres
    r = verify(packing, delta=0.02, method="sequential", seed=0, threshold=1e-3)
    coll, strict = r.collective_test, r.strict_test
    assert r.collective and max(coll.mean_displacement) < 1e-3
    assert max(strict.mean_displacement) > 2 * max(coll.mean_displacement)
