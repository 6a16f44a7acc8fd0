"""Fluid EOS identities and values (Ogarko 2014, ch. 3, Eqs. 3.1-3.16, 3.52, 3.55)."""

import math

import numpy as np
import pytest

from hardpack.distributions import LogNormal, uniform_size, uniform_volume
from hardpack.eos import theory as th
from hardpack.eos.moments import dimensionless_moments, equivalent_bidisperse, equivalent_tridisperse
from hardpack.errors import InvalidInputError

PHI = np.linspace(0.0, 0.64, 65)


def test_monodisperse_reductions():
    """O1 = O2 = 1: BMCSL = SCS = CS and SCSK = BCSK = CSK (Ogarko 2014, Eqs. 3.9-3.12)."""
    cs, k = th.carnahan_starling(PHI), th.csk(PHI)
    for f in (th.bmcsl, th.scs):
        assert f(PHI, 1.0, 1.0) == pytest.approx(cs, rel=1e-14)
    for f in (th.scsk, th.bcsk):
        assert f(PHI, 1.0, 1.0) == pytest.approx(k, rel=1e-14)
    assert th.z_ol(PHI) == pytest.approx(0.5 * (cs + k), rel=1e-14)


def test_published_values():
    """nu = 0.5: 13.000 for all (1 - 2 nu = 0 kills the Kolafa terms); nu = 0.6: CS 27.25, CSK 27.025."""
    for f in (th.carnahan_starling, th.csk, th.bmcsl, th.scs, th.scsk, th.bcsk, th.z_ol):
        assert f(0.5) == pytest.approx(13.0, abs=5e-4)
    assert th.carnahan_starling(0.6) == pytest.approx(27.25, abs=5e-3)
    assert th.csk(0.6) == pytest.approx(27.025, abs=5e-4)


@pytest.mark.parametrize(
    "f, b3",
    [(th.carnahan_starling, 10.0), (th.csk, 10.0), (th.percus_yevick, 10.0), (th.bmcsl, 10.0)],
    ids=["CS", "CSK", "PY", "BMCSL"],
)
def test_virial_coefficients_3d(f, b3):
    """Exact hard-sphere virial series Z = 1 + 4 phi + 10 phi^2 + O(phi^3) (B2, B3 in phi units)."""
    h = 1e-5
    z = f(np.array([h, 2 * h]))
    c2 = (z[1] - 2 * z[0] + 1) / (2 * h**2)  # second difference -> B3
    c1 = (z[0] - 1) / h - c2 * h
    assert c1 == pytest.approx(4.0, abs=1e-3) and c2 == pytest.approx(b3, abs=1e-2)


def test_henderson_2d_virial():
    """Hard disks: Z = 1 + 2 phi + 3.1280 phi^2 + ... (exact B2; B3/B2^2 = 4/3 - sqrt(3)/pi = 0.782);
    Henderson's EOS has 2 and 3.125."""
    h = 1e-5
    z = th.henderson(np.array([h, 2 * h]))
    c2 = (z[1] - 2 * z[0] + 1) / (2 * h**2)
    c1 = (z[0] - 1) / h - c2 * h
    assert c1 == pytest.approx(2.0, abs=1e-3)
    assert c2 == pytest.approx(4 * (4 / 3 - math.sqrt(3) / math.pi), rel=2e-3)


@pytest.mark.parametrize("dist", [uniform_size(5.0), uniform_volume(10.0), LogNormal(0.5)], ids=["US5", "UV10", "LN"])
def test_exact_second_virial_coefficient_of_mixtures(dist):
    """All polydisperse EOS share the exact B2 of additive spheres: Z = 1 + (1 + 3 O1) phi + ..., which
    equals phi sum_ij x_i x_j (a_i + a_j)^3 / (2 <a^3>); checked on the tridisperse equivalent (same O1)."""
    mix = equivalent_tridisperse(dist).mixture
    a, x = np.array(mix.radii), np.array(mix.fractions)
    b2 = np.sum(np.outer(x, x) * (a[:, None] + a[None, :]) ** 3) / (2 * np.sum(x * a**3))
    O1, O2 = dimensionless_moments(dist)
    h = 1e-6
    for f in (th.bmcsl, th.scs, th.scsk, th.bcsk, th.z_ol):
        assert (f(h, O1, O2) - 1) / h == pytest.approx(b2, rel=1e-4)


@pytest.mark.parametrize(
    "dist",
    [uniform_size(5.0), uniform_size(100.0), uniform_volume(4.0), uniform_volume(10.0), LogNormal(0.5)],
    ids=["US5", "US100", "UV4", "UV10", "LN0.5"],
)
def test_bidisperse_equivalent_has_same_eos(dist):
    """Z_bi = Z_poly exactly (Ogarko 2014, Eqs. 3.20-3.21): the binary Jenkins-Mancini pressure with
    BMCSL contact values (Eqs. 3.1-3.5, an independent formula) for (n1, R) of the equivalent equals
    BMCSL with the polydisperse (O1, O2)."""
    eq = equivalent_bidisperse(dist)
    O1, O2 = dimensionless_moments(dist)
    assert th.binary_contact_z(PHI, eq.n1, eq.R) == pytest.approx(th.bmcsl(PHI, O1, O2), rel=1e-11)


def test_binary_contact_values_reduce_to_cs():
    assert th.binary_contact_z(PHI, 0.3, 1.0) == pytest.approx(th.carnahan_starling(PHI), rel=1e-14)
    assert th.binary_contact_z(PHI, 1.0, 2.5) == pytest.approx(th.carnahan_starling(PHI), rel=1e-14)


def test_eos_ordering_polydisperse():
    """Polydispersity lowers Z at fixed phi (O1, O2 < 1); SCS - BMCSL = (O1 - O2) phi^3/(1 - phi)^3 > 0."""
    O1, O2 = dimensionless_moments(uniform_volume(10.0))
    assert np.all(th.bmcsl(PHI[1:], O1, O2) < th.carnahan_starling(PHI[1:]))
    assert np.all(th.scs(PHI[1:], O1, O2) > th.bmcsl(PHI[1:], O1, O2))


def test_free_volume_and_running_estimate():
    phij = 0.648
    phi = np.array([0.3, 0.5, 0.64, 0.6479999])
    z = th.free_volume(phi, phij)
    assert z[0] == pytest.approx(3 / (1 - 0.3 / 0.648))
    assert th.phij_estimate(phi, z) == pytest.approx(phij, rel=1e-9)  # constant on the free-volume law
    assert th.free_volume(phij / 2, phij, d=2) == pytest.approx(4.0)  # Z_fv = 2d at phi_J/2
    # BMCSL: the estimate falls from infinity (Z -> d) to one minimum and then rises again (no plateau,
    # the fluid branch of Fig. 3.2); it stays above phi
    dense = PHI[PHI >= 0.35]  # Z_BMCSL > d = 3 there
    est = th.phij_estimate(dense, th.bmcsl(dense, 0.9, 0.85))
    assert np.count_nonzero(np.diff(np.sign(np.diff(est)))) == 1 and np.all(est > dense)
    assert math.isnan(th.phij_estimate(0.1, 2.0))  # Z <= d: undefined
    with pytest.raises(InvalidInputError):
        th.free_volume(0.65, phij)


def test_empirical_fits():
    """Eqs. 3.15, 3.16 (natural log), 3.52, 3.55 at their published anchors."""
    assert th.phij_fit_uniform_size(np.inf) == pytest.approx(0.6828)  # nu_inf (Ogarko 2014, sec. 3.1.3)
    assert th.phij_fit_uniform_size(1.2 + 1e-12) < th.phij_fit_uniform_size(2.0) < 0.6828
    assert th.phij_fit_lognormal(0.0) == pytest.approx(0.6373)  # phi_RCP = nu_max(0) from data (below Eq. 3.52)
    # the printed fits evaluated here (not printed values)
    assert th.phij_fit_uniform_size([2, 4, 10]) == pytest.approx([0.6664, 0.6777, 0.6819], abs=5e-5)
    assert th.phij_fit_uniform_volume([2, 4, 10]) == pytest.approx([0.6693, 0.6965, 0.7509], abs=5e-5)
    assert th.phij_fit_lognormal([0.2, 0.5, 1.0]) == pytest.approx([0.6497, 0.7009, 0.7771], abs=5e-5)
    # both log-normal fits describe the same data to 0.7 % and 0.4 %, so they agree within 1.1 %
    s = np.linspace(0, 1, 101)
    assert np.max(np.abs(th.phij_fit_lognormal_alt(s) / th.phij_fit_lognormal(s) - 1)) < 0.011


@pytest.mark.filterwarnings("ignore:.*fitted range")  # omega < 1.2 lies outside the fitted data
def test_fit_slopes_vanish_at_omega_one():
    """The fits enforce d nu_max / d(1/omega) = 0 at omega = 1 (Ogarko 2014, below Eqs. 3.15 and
    3.16); for Eq. 3.16 this holds only with the natural log: with log10 the shape factor
    F(x = 1/omega) would have dF/dx = 2 - 2/ln 10 = 1.13 at x = 1 instead of 2 - 2 = 0 (derived here)."""
    eps = 1e-6
    for f in (th.phij_fit_uniform_size, th.phij_fit_uniform_volume):
        slope = (f(1 / (1 - eps)) - f(1.0)) / eps
        assert abs(slope) < 1e-4
    w = 1 / (1 - eps)
    log10_variant = (1 / w - 1 / w**2 + 1 / w**3) * (1 + 2 * np.log10(w))
    assert abs((log10_variant - 1) / eps) > 0.1


def test_fit_range_warnings_and_refusals():
    with pytest.warns(UserWarning, match="fitted range"):
        th.phij_fit_uniform_volume(20.0)
    with pytest.warns(UserWarning, match="fitted range"):
        th.phij_fit_lognormal(1.5)
    with pytest.raises(InvalidInputError):
        th.phij_fit_uniform_size(0.5)
    with pytest.raises(InvalidInputError):
        th.carnahan_starling(1.0)
    with pytest.raises(InvalidInputError):
        th.bmcsl(0.3, 0.8, 0.9)  # O2 > O1 is not a size distribution
    with pytest.raises(InvalidInputError):
        th.henderson(-0.1)


def test_hard_disk_virial_b3_from_its_cluster_integral():
    """B_3 = (1/3) x (measure of three mutually overlapping unit disks) = (1/3) int_0^1 2 pi r
    A_lens(r) dr, A_lens the overlap area of two unit disks; B_2 = pi/2. The series' B_3 must match
    that quadrature, and its low-density expansion must start 1 + 2 phi + 4 B_3/B_2^2 phi^2."""
    from scipy.integrate import quad

    def lens(d):
        return 2 * math.acos(d / 2) - 0.5 * d * math.sqrt(4 - d * d)

    b3 = quad(lambda r: 2 * math.pi * r * lens(r), 0, 1, epsabs=1e-13)[0] / 3
    assert th.HARD_DISK_VIRIAL[1] == pytest.approx(b3 / (math.pi / 2) ** 2, rel=1e-10)
    h = 1e-4
    z = th.hard_disk_virial(np.array([h, 2 * h]))
    c2 = (z[1] - 2 * z[0] + 1) / (2 * h**2)
    c1 = (z[0] - 1) / h - c2 * h
    assert c1 == pytest.approx(2.0, abs=1e-6) and c2 == pytest.approx(4 * th.HARD_DISK_VIRIAL[1], rel=1e-3)


def test_hard_disk_virial_truncation_bounds_the_next_terms():
    """The bound covers the series' missing B_11 x^10 for any B_11 <= r B_10 (the ratio trend) and
    grows with phi; it is the docstring's 1e-4 at phi = 0.3."""
    r = th.HARD_DISK_VIRIAL[-1] / th.HARD_DISK_VIRIAL[-2]
    bounds = th.hard_disk_virial_truncation(np.array([0.1, 0.2, 0.3, 0.4]))
    assert np.all(np.diff(bounds) > 0)
    for phi in (0.1, 0.2, 0.3, 0.4):
        x = 2 * phi
        assert th.hard_disk_virial_truncation(phi) > r * th.HARD_DISK_VIRIAL[-1] * x**10
    assert th.hard_disk_virial_truncation(0.3) == pytest.approx(1.0e-4, rel=0.01)
    with pytest.raises(InvalidInputError, match=r"\[0, 0.5\)"):
        th.hard_disk_virial(0.5)


def test_hard_disk_solid_is_the_free_volume_divergence_plus_constants():
    """Near close packing Z -> 2/a + C_0 with a = phi_cp/phi - 1 (the 2D free-volume pole); at
    phi = 0.84 the printed constants give 2/a + 1.90 + 0.67 a with error 0.01 + 0.07 a."""
    cp = math.pi / math.sqrt(12)
    for a in (1e-3, 0.05, 0.1):
        z, err = th.hard_disk_solid(cp / (1 + a))
        assert z == pytest.approx(2 / a + 1.90 + 0.67 * a, rel=1e-9)
        assert err == pytest.approx(0.01 + 0.07 * a, rel=1e-12)
    z, _ = th.hard_disk_solid(np.array([0.80, 0.84]))
    assert np.all(np.diff(z) > 0) and z[1] == pytest.approx(27.07, abs=0.01)
    with pytest.raises(InvalidInputError):
        th.hard_disk_solid(0.91)
