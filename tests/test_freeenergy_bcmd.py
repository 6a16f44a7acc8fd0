"""BCMD (Donev ch. 6 sec. 6.3) against exactly known free energies."""

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.bcmd import run_bcmd
from hardpack.freeenergy.ladder import disjoint_cells
from hardpack.geometry.lattices import lattice_packing

FCC_EXCESS_0545 = 5.91916  # Delta f_FCC(phi = 0.545), N -> infinity (Donev 2006, Sec. 6.4.1)
FCC_JAMMING = 2.160  # [f_J - f_c^J]_FCC, N -> infinity (Donev 2006, Sec. 6.4.1)


@pytest.mark.parametrize("name,reps", [("fcc", (2, 2, 2)), ("triangular", (4, 4))])
@pytest.mark.parametrize("frozen", ["particle", "cm"])
def test_disjoint_cells_reference(name, reps, frozen):
    # Half-size spheres: the cells (radius (1 + dmu) R) stay disjoint for dmu <= 1, so every
    # sphere is an independent billiard in a shrinking ball and (d/2) ln(K/K0) = d ln(dmu0/dmu1)
    # exactly up to the adiabatic error O(wall speed / v) ~ 1e-4 (derived here); the
    # CM-frame K differs from the total K by O(1/N) fluctuations of the CM momentum, hence the
    # looser tolerance there. The reference f_c = -d ln dmu - ln V_p (Eq. 6.10).
    res, exact = disjoint_cells(name, reps, frozen)
    d = res.to_dataset().attrs["dim"]
    tol = 2e-3 if frozen == "particle" else 0.05
    assert res.delta_f == pytest.approx(exact, abs=tol)
    vp = np.pi / 6 if d == 3 else np.pi / 4  # unit-diameter particle (length unit = diameter)
    assert res.f_c == pytest.approx(-d * np.log(0.05) - np.log(vp), rel=1e-12)
    ds = res.to_dataset()
    # cell pressure p_c = mu / dmu for disjoint cells (derived here; Fig. 6.4's asymptote);
    # per-segment noise is a few per cent, so compare the mean ratio (1 %)
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


def _extrapolated(state):
    """BCMD of FCC at N = 32, 108, 256 (two seeds each), extrapolated to N -> infinity with
    a + b ln N / N (the leading finite-size term, Donev 2006, Sec. 6.4.1): (a, its fit error)."""
    from hardpack.validation.freeenergy import finite_size_extrapolation

    n, values = [], []
    for reps in (2, 3, 4):
        p = lattice_packing("fcc", (reps,) * 3)
        for seed in (1, 2):
            if state == "melting":
                # lattice-centred cells, dmu_max = 1, theta = 1 (the paper's schedule), gamma0 = 3e-3
                q = p.replace(radii=p.radii * (0.545 / p.phi) ** (1 / 3))
                res = run_bcmd(q, dmu_max=1.0, gamma0=3e-3, theta=1.0, seed=seed)
                assert res.to_dataset().attrs["dmu_min"] == pytest.approx((0.74048048969 / 0.545) ** (1 / 3) - 1, rel=1e-9)
                values.append(res.excess)
            else:
                # at contact shrunk by delta = 1e-6, dmu_max = 10 delta, gamma0 = 1e-3, theta = 0.5
                q = p.replace(radii=p.radii * (1 - 1e-6))
                res = run_bcmd(q, dmu_max=1e-5, gamma0=1e-3, theta=0.5, seed=seed)
                assert res.to_dataset().attrs["dmu_min"] == pytest.approx(1e-6, rel=1e-5)
                values.append(res.delta_f)
            n.append(p.n_particles)
    a, err, _ = finite_size_extrapolation(n, values)
    return a, err


@pytest.mark.slow
def test_fcc_melting_point_excess():
    """The N -> infinity excess free energy of FCC at phi = 0.545 against the published 5.91916(1):
    within its stated error plus two of our fit errors."""
    a, err = _extrapolated("melting")
    assert abs(a - FCC_EXCESS_0545) <= 1e-5 + 2 * err and err < 0.01


@pytest.mark.slow
def test_fcc_jamming_limit():
    """The N -> infinity jamming constant f_J - f_c^J of FCC (Eq. 6.18) against the published
    2.160 +- 0.001: within that error plus two of our fit errors."""
    a, err = _extrapolated("jamming")
    assert abs(a - FCC_JAMMING) <= 0.001 + 2 * err and err < 0.01


def test_velocity_redraws_are_chained():
    # thermostat of Donev 2006, sec. 6.3.5.1: velocities re-drawn whenever K doubled; the chained
    # sum of ln(K_end/K_start) must still give the exact disjoint-cell d ln(dmu0/dmu1)
    # (measured within 2e-4 over three seeds; tolerance as in the test above)
    p = lattice_packing("fcc", (2, 2, 2))
    p = p.replace(radii=p.radii * 0.5)
    res = run_bcmd(p, dmu_max=0.5, dmu_min=0.05, gamma0=2e-3, theta=0.0, seed=1, reset_ratio=2.0)
    assert res.to_dataset().attrs["n_redraws"] >= 5  # K grows by 10^2 overall
    assert res.delta_f == pytest.approx(3 * np.log(10.0), abs=2e-3)


def test_partial_run_has_no_reference():
    p = lattice_packing("fcc", (2, 2, 2))
    p = p.replace(radii=p.radii * (0.545 / p.phi) ** (1 / 3))
    res = run_bcmd(p, dmu_max=1.0, dmu_min=0.9, gamma0=1e-2, partial=True)
    assert np.isnan(res.f_c) and np.isnan(res.excess)
    assert res.delta_f > 0  # shrinking cells always heat the system
