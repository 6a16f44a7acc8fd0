"""phi_J from Z(phi): free-volume fit and plateau test (Ogarko 2014, Eq. 3.14, sec. 3.1.3, Fig. 3.8)."""

import numpy as np
import pytest

from hardpack.distributions import uniform_size
from hardpack.eos import theory as th
from hardpack.eos.moments import dimensionless_moments
from hardpack.eos.phij import fit_free_volume
from hardpack.errors import InvalidInputError

PHI_J = 0.6482


def free_volume_data(rng, noise=0.01, z_lo=1e2, z_hi=1e10, n=120, d=3):
    """Exact free-volume law sampled at log-spaced Z, with multiplicative Gaussian noise on Z."""
    z_true = np.logspace(np.log10(z_lo), np.log10(z_hi), n)
    phi = PHI_J * (1 - d / z_true)
    return phi, z_true * (1 + noise * rng.standard_normal(n))


def test_recovers_phij_from_noisy_free_volume_data():
    """1 % noise on Z up to 1e10: phi_J within 4 standard errors, and the error is ~1e-12 (the gap
    phi_J - phi at Z = 1e10 is 2e-10, so the fit resolves phi_J far below the gap)."""
    phi, z = free_volume_data(np.random.default_rng(7))
    fit = fit_free_volume(phi, z, decades=4)
    assert abs(fit.phi_j - PHI_J) <= 4 * fit.stderr
    assert 1e-13 < fit.stderr < 1e-11
    assert fit.plateau
    assert fit.z_range[0] >= 1e6 * 0.95 and fit.n_points == 60  # last four decades of eight
    assert fit.phi_range[1] < PHI_J


def test_error_estimate_has_nominal_coverage():
    """Over 200 independent noisy data sets about 95 % of the fits lie within 2 reported standard
    errors (binomial spread +-1.5 %), and the plateau test (3 sigma) rarely fires falsely."""
    rng = np.random.default_rng(11)
    inside = plateaus = 0
    for _ in range(200):
        phi, z = free_volume_data(rng, n=60)
        fit = fit_free_volume(phi, z, decades=4)
        inside += abs(fit.phi_j - PHI_J) <= 2 * fit.stderr
        plateaus += fit.plateau
    assert 0.89 <= inside / 200 <= 0.99
    assert plateaus >= 190


def test_absolute_sigma():
    """With the true sigma_Z given, chi^2_red ~ 1 and the error is not rescaled."""
    rng = np.random.default_rng(3)
    phi, z = free_volume_data(rng, noise=0.02, n=400)
    z_true = 3 / (1 - phi / PHI_J)
    fit = fit_free_volume(phi, z, decades=3, sigma_z=0.02 * z_true)
    assert fit.chi2_red == pytest.approx(1.0, abs=0.3)
    assert abs(fit.phi_j - PHI_J) <= 4 * fit.stderr


@pytest.mark.parametrize("noise", [0.0, 0.005])
def test_bmcsl_data_do_not_plateau(noise):
    """A fluid EOS (BMCSL, US omega = 2) has no free-volume regime: the running estimate drifts upward over
    the last decade of Z (phi 0.50-0.64) and the fit says so."""
    O1, O2 = dimensionless_moments(uniform_size(2.0))
    phi = np.linspace(0.50, 0.64, 60)
    z = th.bmcsl(phi, O1, O2) * (1 + noise * np.random.default_rng(5).standard_normal(phi.size))
    fit = fit_free_volume(phi, z, decades=1)
    assert not fit.plateau
    assert fit.drift > 0.01  # phi_J^est rises by > 0.01 across the range
    assert fit.drift > 10 * fit.drift_err


def test_fit_range_excludes_fluid_branch():
    """Fluid data (BMCSL up to phi = 0.6, Z <~ 30) followed by a free-volume approach to phi_J with 0.2 %
    noise: the last three decades give phi_J with a plateau and chi^2_red ~ 1 (true errors given); a fit
    over all nine decades mixes in the fluid branch, which the goodness of fit exposes (chi^2_red >> 1)."""
    O1, O2 = dimensionless_moments(uniform_size(2.0))
    phi_f = np.linspace(0.40, 0.60, 40)
    phi_j, z_j = free_volume_data(np.random.default_rng(2), noise=0.002, z_lo=1e2, z_hi=1e9, n=80)
    phi = np.concatenate([phi_f, phi_j])
    z = np.concatenate([th.bmcsl(phi_f, O1, O2), z_j])
    sigma = 0.002 * np.concatenate([th.bmcsl(phi_f, O1, O2), 3 / (1 - phi_j / PHI_J)])
    good = fit_free_volume(phi, z, decades=3, sigma_z=sigma)
    assert good.plateau and abs(good.phi_j - PHI_J) <= 4 * good.stderr
    assert good.chi2_red < 2
    assert fit_free_volume(phi, z, decades=9, sigma_z=sigma).chi2_red > 100


def test_refusals():
    phi, z = free_volume_data(np.random.default_rng(0), n=10)
    with pytest.raises(InvalidInputError, match="need at least 3"):
        fit_free_volume(phi, z, decades=0.1)
    with pytest.raises(InvalidInputError):
        fit_free_volume(phi, z[:-1])
    with pytest.raises(InvalidInputError):
        fit_free_volume(np.append(phi, np.nan), np.append(z, 1e3))
    with pytest.raises(InvalidInputError):
        fit_free_volume(phi, z, sigma_z=-1.0)
