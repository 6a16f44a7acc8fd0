"""Equilibrium equations of state from NVE event-driven MD (Gamma = 0), against standard fluid EOS:

- 3D monodisperse: Carnahan-Starling Z = (1 + phi + phi^2 - phi^3) / (1 - phi)^3, accurate to a
  few 0.1 % up to freezing (phi = 0.494);
- 2D disks: Henderson Z = (1 + phi^2/8) / (1 - phi)^2, accurate to < 0.5 % for phi <= 0.5;
- 3D polydisperse: BMCSL Z = 1/(1-phi) + 3 O1 phi/(1-phi)^2 + O2 phi^2 (3-phi)/(1-phi)^3 with
  O1 = <a><a^2>/<a^3>, O2 = <a^2>^3/<a^3>^2 (Ogarko 2014, Eqs. 3.6 and 3.9).

Each run has N = 500 and enough collisions for a standard error below 0.25 % of Z, so the 1 %
tolerance (which also absorbs O(1/N) finite-size effects) is meaningful.
"""

import numpy as np
import pytest

from hardpack.distributions import monodisperse, uniform_size
from hardpack.initial import random_packing
from hardpack.md import StopCriteria, compress, equilibrate


def carnahan_starling(phi):
    return (1 + phi + phi**2 - phi**3) / (1 - phi) ** 3


def henderson(phi):
    return (1 + phi**2 / 8) / (1 - phi) ** 2


def bmcsl(phi, radii):
    m1, m2, m3 = (np.mean(radii**k) for k in (1, 2, 3))
    o1, o2 = m1 * m2 / m3, m2**3 / m3**2
    return 1 / (1 - phi) + 3 * o1 * phi / (1 - phi) ** 2 + o2 * phi**2 * (3 - phi) / (1 - phi) ** 3


def fluid(d, distribution, phi, seed=3, n=500):
    """RSA well below saturation, then a fast LS compression exactly to phi."""
    packing = random_packing(n, d, distribution, min(phi, 0.15 if d == 3 else 0.3), seed=seed)
    if phi > packing.phi:
        packing = compress(packing, 0.1, seed=1, stop=StopCriteria(max_pressure=None, target_phi=phi)).packing
    return packing


def check_eos(packing, reference, n_collisions):
    res = equilibrate(packing, seed=2, n_collisions=n_collisions)
    assert res.phi == pytest.approx(packing.phi, rel=1e-12)  # NVE: phi fixed
    assert res.Z_err < 0.0025 * reference
    assert res.Z == pytest.approx(reference, rel=0.01)
    return res


@pytest.mark.parametrize("phi", [0.2, 0.3])
def test_3d_carnahan_starling(phi):
    check_eos(fluid(3, monodisperse(0.5), phi), carnahan_starling(phi), 200_000)


@pytest.mark.slow
@pytest.mark.parametrize("phi", [0.4, 0.45])
def test_3d_carnahan_starling_dense(phi):
    check_eos(fluid(3, monodisperse(0.5), phi), carnahan_starling(phi), 500_000)


@pytest.mark.parametrize("phi", [0.3, 0.5])
def test_2d_henderson(phi):
    check_eos(fluid(2, monodisperse(0.5), phi), henderson(phi), 300_000)


@pytest.mark.slow
def test_3d_polydisperse_bmcsl():
    packing = fluid(3, uniform_size(2.0), 0.4)
    check_eos(packing, bmcsl(0.4, packing.radii), 500_000)
