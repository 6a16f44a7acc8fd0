"""BCMD (Donev ch. 6 sec. 6.3) against exactly known free energies."""

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.bcmd import run_bcmd
from hardpack.freeenergy.ladder import disjoint_cells
from hardpack.geometry.lattices import lattice_packing

FCC_EXCESS_0545 = 5.91916  # Delta f_FCC(phi = 0.545), [C:1008-1010] (N -> infinity)
FCC_JAMMING = 2.160  # [f_J - f_c^J]_FCC, [C:1012-1018] (N -> infinity)


@pytest.mark.parametrize("name,reps", [("fcc", (2, 2, 2)), ("triangular", (4, 4))])
@pytest.mark.parametrize("frozen", ["particle", "cm"])
def test_disjoint_cells_reference(name, reps, frozen):
    # Half-size spheres: the cells (radius (1 + dmu) R) stay disjoint for dmu <= 1, so every
    # sphere is an independent billiard in a shrinking ball and (d/2) ln(K/K0) = d ln(dmu0/dmu1)
    # exactly up to the adiabatic error O(wall speed / v) ~ 1e-4 (note sec. 5.2 item 1); the
    # CM-frame K differs from the total K by O(1/N) fluctuations of the CM momentum, hence the
    # looser tolerance there. The reference f_c = -d ln dmu - ln V_p (Eq. 6.10).
    res, exact = disjoint_cells(name, reps, frozen)
    d = res.dataset.attrs["dim"]
    tol = 2e-3 if frozen == "particle" else 0.05
    assert res.delta_f == pytest.approx(exact, abs=tol)
    vp = np.pi / 6 if d == 3 else np.pi / 4  # unit-diameter particle (length unit = diameter)
    assert res.f_c == pytest.approx(-d * np.log(0.05) - np.log(vp), rel=1e-12)
    ds = res.dataset
    # cell pressure p_c = mu / dmu for disjoint cells (note sec. 1.5); per-segment noise is a few
    # per cent, so compare the mean ratio (1 %)
    ratio = ds.p_c / ((1 + ds.dmu_mid) / ds.dmu_mid)
    assert float(ratio.mean()) == pytest.approx(1.0, abs=0.01)
    assert ds.attrs["final_min_gap"] > 0
    assert ds.attrs["n_pair"] == 0


def test_refusals():
    p = lattice_packing("fcc", (2, 2, 2))  # touching spheres: cells are never disjoint
    with pytest.raises(InvalidInputError, match="never disjoint"):
        run_bcmd(p, dmu_max=0.1)
    q = p.replace(radii=p.radii * 0.9)
    with pytest.raises(InvalidInputError, match="disjoint-cell point"):
        run_bcmd(q, dmu_max=0.5, dmu_min=0.3)
    with pytest.raises(InvalidInputError, match="frozen"):
        run_bcmd(q, dmu_max=0.5, frozen="box")
    with pytest.raises(InvalidInputError, match="gamma0"):
        run_bcmd(q, dmu_max=0.5, gamma0=-1.0)


@pytest.mark.slow
def test_fcc_melting_point_excess():
    # FCC, N = 108, lattice-centred cells, dmu_max = 1, theta = 1 (the paper's schedule,
    # [C:1010-1011]) but gamma0 = 3e-3 (3x faster, to fit the slow-test budget), one frozen
    # particle. Measured 5.9028 / 5.8962 / 5.9004 (seeds 1-3; 5.9011 mean at gamma0 = 1e-3).
    # The published value is the N -> infinity limit; the full study's fit a + b ln N / N over
    # N = 32..500 (a = 5.916, b = -0.35) puts N = 108 at 5.901, 0.018 below it, hence the
    # one-sided band of 0.03 (offset plus seed scatter ~0.004 and the gamma0 bias ~0.002).
    p = lattice_packing("fcc", (3, 3, 3))
    p = p.replace(radii=p.radii * (0.545 / p.phi) ** (1 / 3))
    res = run_bcmd(p, dmu_max=1.0, gamma0=3e-3, theta=1.0, seed=2)
    assert res.dataset.attrs["dmu_min"] == pytest.approx(
        (0.74048048969 / 0.545) ** (1 / 3) - 1, rel=1e-9
    )
    assert FCC_EXCESS_0545 - 0.03 < res.excess < FCC_EXCESS_0545


@pytest.mark.slow
def test_fcc_jamming_limit():
    # FCC at contact shrunk by delta = 1e-6, cells at the sites, dmu_max = 10 delta,
    # gamma0 = 1e-3, theta = 0.5 ([C:1017-1025]); Delta f = f_J - f_c^J (Eq. 6.18). N = 108 with
    # one frozen particle: measured 2.1768 (seed 1; 2.1812 mean of seeds 1-3). The full study's
    # fit over N = 32..500 (a = 2.161, b = +0.46) puts N = 108 at 2.181, 0.021 above the
    # published value, hence the one-sided band of 0.03.
    delta = 1e-6
    p = lattice_packing("fcc", (3, 3, 3))
    p = p.replace(radii=p.radii * (1 - delta))
    res = run_bcmd(p, dmu_max=10 * delta, gamma0=1e-3, theta=0.5, seed=1)
    assert res.dataset.attrs["dmu_min"] == pytest.approx(delta, rel=1e-5)
    assert FCC_JAMMING < res.delta_f < FCC_JAMMING + 0.03


def test_velocity_redraws_are_chained():
    # thermostat of [C:918-923]: velocities re-drawn whenever K doubled; the chained
    # sum of ln(K_end/K_start) must still give the exact disjoint-cell d ln(dmu0/dmu1)
    # (measured within 2e-4 over three seeds; tolerance as in the test above)
    p = lattice_packing("fcc", (2, 2, 2))
    p = p.replace(radii=p.radii * 0.5)
    res = run_bcmd(p, dmu_max=0.5, dmu_min=0.05, gamma0=2e-3, theta=0.0, seed=1, reset_ratio=2.0)
    assert res.dataset.attrs["n_redraws"] >= 5  # K grows by 10^2 overall
    assert res.delta_f == pytest.approx(3 * np.log(10.0), abs=2e-3)


def test_partial_run_has_no_reference():
    p = lattice_packing("fcc", (2, 2, 2))
    p = p.replace(radii=p.radii * (0.545 / p.phi) ** (1 / 3))
    res = run_bcmd(p, dmu_max=1.0, dmu_min=0.9, gamma0=1e-2, partial=True)
    assert np.isnan(res.f_c) and np.isnan(res.excess)
    assert res.delta_f > 0  # shrinking cells always heat the system
