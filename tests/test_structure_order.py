"""Order metrics (hardpack.structure.order): Steinhardt Q6, psi6, T, q6 crystallinity."""

import math

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import unit_ball_volume
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.structure.order import (
    coordination_defects,
    crystallinity,
    order_map,
    psi6,
    steinhardt,
    translational_order,
)


@pytest.mark.parametrize("name, reps, q6", [
    ("fcc", 3, 0.57452), ("hcp", (4, 4, 3), 0.48476), ("bcc", 3, 0.51069), ("sc", 4, 0.35355),
])
def test_steinhardt_q6_of_crystals(name, reps, q6):
    """Steinhardt, Nelson & Ronchetti (1983) values (BCC with its 8 + 6 neighbours); SC is
    exactly sqrt(2)/4 = 0.353553."""
    ds = steinhardt(lattice_packing(name, reps))
    assert abs(float(ds.Q6) - q6) < 1e-5
    np.testing.assert_allclose(ds.q6.values, q6, atol=1e-5)
    if name == "sc":
        assert abs(float(ds.Q6) - math.sqrt(2) / 4) < 1e-12


def test_q6_of_isotropic_bonds_is_small(ideal_gas):
    """Random bond directions: <Y_6m> over B bonds has |.|^2 ~ 1/(4 pi B) per m, so
    Q6 ~ sqrt(13 / (13 B)) = 1/sqrt(B)."""
    p = ideal_gas(3000, 3, 12.0, radii=0.5)
    ds = steinhardt(p, neighbours=1.6)
    bonds = int(ds.n_bonds.sum())
    assert float(ds.Q6) < 3 / math.sqrt(bonds)


def test_psi6_triangular_and_square():
    ds = psi6(lattice_packing("triangular", (6, 7)))
    assert abs(float(ds.psi6_global) - 1) < 1e-12
    np.testing.assert_allclose(ds.psi6_abs.values, 1.0, atol=1e-12)
    assert float(psi6(lattice_packing("square", 6)).psi6_local_mean) < 1e-12  # 1 - 1 + 1 - 1


def test_coordination_defects_of_the_triangular_lattice_and_of_a_vacancy():
    crystal = lattice_packing("triangular", (8, 9))  # 72 disks
    assert coordination_defects(crystal) == 0.0
    # a vacancy: its six neighbours lose a bond and the triangulation of the hexagonal hole adds
    # three diagonals, so 3 to 6 of the 71 disks are not six-fold (which depends on the diagonals).
    # The shrunken, jittered disks make the triangulation unique (the perfect hole is cocircular).
    jitter = np.random.default_rng(0).uniform(-1e-3, 1e-3, crystal.positions.shape)
    keep = np.arange(1, crystal.n_particles)
    vacancy = Packing(crystal.positions[keep] + jitter[keep], 0.99 * crystal.radii[keep], crystal.lattice)
    assert 3 / 71 <= coordination_defects(vacancy) <= 6 / 71
    with pytest.raises(InvalidInputError, match="2"):
        coordination_defects(lattice_packing("fcc", 2))


@pytest.mark.parametrize("name, reps", [("fcc", 4), ("triangular", (8, 9)), ("D4", 2)])
def test_translational_order_is_one_for_the_reference_crystal(name, reps):
    assert abs(translational_order(lattice_packing(name, reps)) - 1) < 1e-12


def test_translational_order_of_ideal_gas_vanishes_within_counting_noise(ideal_gas):
    """Numerator = sum_i (n_i - n_i^ideal) with n_i = 2 c_i / N and c ~ Poisson pair counts:
    sd = sqrt(2 sum n_i^ideal / N); the FCC denominator is known, so T < 5 sd / denominator."""
    n, length = 4000, 15.0
    rho = n / length**3
    a1 = (math.sqrt(2) / rho) ** (1 / 3)
    shells = np.sqrt(np.arange(1, 8))
    w = 0.98 * np.diff(shells).min()  # the default width
    ideal = rho * unit_ball_volume(3) * (((shells + w / 2) * a1) ** 3 - ((shells - w / 2) * a1) ** 3)
    fcc_counts = np.array([12, 6, 24, 12, 24, 8, 48])
    sd = math.sqrt(2 * ideal.sum() / n) / (fcc_counts - ideal).sum()
    values = [translational_order(ideal_gas(n, 3, length, seed=s)) for s in range(4)]
    assert max(values) < 5 * sd
    assert sd < 0.05  # the test can tell a gas from an ordered packing
    assert 0.3 < translational_order(lattice_packing("bcc", 4)) < 0.9


def test_translational_order_refuses_overlapping_shells():
    with pytest.raises(InvalidInputError):
        translational_order(lattice_packing("fcc", 2), width=0.3)


def test_crystallinity_crystal_versus_gas(ideal_gas):
    """Ogarko's criterion with regular-triangulation neighbours: a slightly perturbed FCC
    (octahedra split arbitrarily, 14 neighbours on average) is fully solid-like; the ideal
    gas (random q6 vectors) has essentially no solid-like particle."""
    rng = np.random.default_rng(1)
    fcc = lattice_packing("fcc", 4)
    shaken = fcc.replace(positions=fcc.positions + rng.normal(0, 0.02, fcc.positions.shape),
                         radii=fcc.radii * 0.8)
    assert float(crystallinity(shaken).crystallinity) == 1.0
    gas = crystallinity(ideal_gas(1500, 3, 11.0))
    assert float(gas.crystallinity) < 0.01


def test_order_map_pairs_phi_with_t(ideal_gas):
    fcc = lattice_packing("fcc", 3)
    gas = ideal_gas(2000, 3, 12.0)
    ds = order_map([fcc, gas])
    np.testing.assert_allclose(ds.phi.values, [math.pi / math.sqrt(18), gas.phi])
    assert abs(ds.T.values[0] - 1) < 1e-12 and ds.T.values[1] < 0.1
    with pytest.raises(InvalidInputError):
        order_map([])


def test_dimension_checks():
    with pytest.raises(InvalidInputError):
        steinhardt(lattice_packing("square", 3))
    with pytest.raises(InvalidInputError):
        psi6(lattice_packing("sc", 3))
    with pytest.raises(InvalidInputError):
        steinhardt(lattice_packing("sc", 3), neighbours="voronoi")
