"""Reference curves of the FCC free energy (hardpack.freeenergy.crystal) against numbers
derived here from Donev 2006, sec. 6.4.1, and exact integrals."""

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.crystal import (
    PHI_CP,
    cell_limit_excess,
    cell_offset,
    disjoint_dmu,
    eos_excess,
    free_volume_z,
)


def test_note_numbers():
    # derived here from the melting value of Donev 2006, sec. 6.4.1: Delta mu_min = 0.10757 at
    # phi = 0.545, f_c = 7.3358 and the expected (3/2) ln(K/K0) = 5.91916... -> 2.3766 (f = 4.9592)
    assert disjoint_dmu(0.545) == pytest.approx(0.10757, abs=1e-5)
    assert cell_offset(0.545) - 5.91916 == pytest.approx(2.3766, abs=2e-4)
    # derived here from [f_J - f_c^J]_FCC = 2.160: excess -> -3 ln(1 - phi/phi_cp) + 2.436 as phi -> phi_cp
    phi = PHI_CP * (1 - 1e-7)
    assert cell_limit_excess(phi) == pytest.approx(-3 * np.log(1e-7) + 2.436, abs=2e-3)


def test_eos_integral_is_exact_for_the_free_volume_pressure():
    # Z = Z_fv + c: the integral is -3 ln((1-x)/(1-x0)) + c ln(phi/phi0); the spline of c/phi
    # through 9 points is accurate to ~1e-5 here
    phi = np.array([0.545, 0.57, 0.60, 0.63, 0.66, 0.69, 0.71, 0.725, 0.735])
    c = 1.3
    x, x0 = (phi / PHI_CP) ** (1 / 3), (0.545 / PHI_CP) ** (1 / 3)
    exact = 5.0 - 3 * np.log((1 - x) / (1 - x0)) + c * np.log(phi / 0.545)
    got = eos_excess(phi, free_volume_z(phi) + c, excess0=5.0)
    np.testing.assert_allclose(got, exact, atol=1e-4)
    # the cell limit is the free-volume integral with its own constant
    shape = cell_limit_excess(phi) - cell_limit_excess(0.545)
    np.testing.assert_allclose(eos_excess(phi, free_volume_z(phi), excess0=0.0), shape, atol=1e-9)
    at = np.linspace(0.545, 0.735, 7)
    np.testing.assert_allclose(
        eos_excess(phi, free_volume_z(phi) + c, excess0=5.0, at=at),
        5.0 - 3 * np.log((1 - (at / PHI_CP) ** (1 / 3)) / (1 - x0)) + c * np.log(at / 0.545),
        atol=1e-4,
    )


def test_eos_refusals():
    with pytest.raises(InvalidInputError, match="phi0"):
        eos_excess([0.6, 0.65, 0.7], [10.0, 20.0, 50.0])
    with pytest.raises(InvalidInputError, match="within"):
        eos_excess([0.545, 0.6, 0.7], [11.0, 20.0, 50.0], at=[0.72])
