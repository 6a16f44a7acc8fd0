"""Size distributions: analytic moments (Ogarko Eqs. 3.23-3.25, 3.44) and systematic sampling."""

import math

import numpy as np
import pytest

from hardpack import InvalidInputError
from hardpack.distributions import (
    Discrete,
    LogNormal,
    PowerLaw,
    bidisperse,
    from_spec,
    monodisperse,
    uniform_size,
    uniform_volume,
)


def O1_O2(dist):
    m1, m2, m3 = dist.moment(1), dist.moment(2), dist.moment(3)
    return m1 * m2 / m3, m2**3 / m3**2


@pytest.mark.parametrize("omega", [1.2, 2, 4, 10, 100])
def test_us_moments_match_ogarko_eq_3_23(omega):
    w0 = (omega - 1) / (omega + 1)
    o1, o2 = O1_O2(uniform_size(omega))
    assert o1 == pytest.approx(1 - (2 / 3) * w0**2 / (1 + w0**2), rel=1e-12)
    assert o2 == pytest.approx((3 + w0**2) ** 3 / (27 * (1 + w0**2) ** 2), rel=1e-12)


@pytest.mark.parametrize("omega", [1.2, 2, 4, 10, 100])
def test_uv_moments_match_ogarko_eqs_3_24_and_3_44(omega):
    dist = uniform_volume(omega)
    o1, o2 = O1_O2(dist)
    ln = math.log(omega)
    assert o1 == pytest.approx(2 * omega * ln / (omega**2 - 1), rel=1e-12)
    assert o2 == pytest.approx(2 * omega**2 * ln**3 / ((omega - 1) ** 3 * (omega + 1)), rel=1e-12)
    w0 = (omega - 1) / (omega + 1)
    m = [dist.moment(k) / dist.moment(1) ** k for k in range(6)]
    assert m[2] == pytest.approx(ln / (2 * w0), rel=1e-12)
    assert m[3] == pytest.approx((1 + omega) ** 2 / (4 * omega), rel=1e-12)
    assert m[4] == pytest.approx((1 + omega) ** 4 / (16 * omega**2), rel=1e-12)
    assert m[5] == pytest.approx((1 + omega) ** 4 * (1 + omega + omega**2) / (48 * omega**3), rel=1e-12)
    # support (Eq. 3.43): a_min = (omega + 1) <a> / (2 omega)
    assert dist.support[0] == pytest.approx((omega + 1) / (2 * omega))


@pytest.mark.parametrize("sigma", [0.1, 0.5, 1.0])
def test_lognormal_moments_eq_3_25(sigma):
    o1, o2 = O1_O2(LogNormal(sigma))
    assert o1 == pytest.approx(math.exp(-2 * sigma**2), rel=1e-12)
    assert o2 == pytest.approx(math.exp(-3 * sigma**2), rel=1e-12)


@pytest.mark.parametrize("dist", [uniform_size(4), uniform_volume(10), PowerLaw(3, -2), PowerLaw(5, -1),
                                  PowerLaw(2, 1.5), bidisperse(1.4, 0.5)])
def test_moments_against_quadrature_and_normalisation(dist):
    assert dist.moment(0) == pytest.approx(1)
    assert dist.moment(1) == pytest.approx(1)  # normalised to <a> = 1
    if not isinstance(dist, Discrete):
        from scipy.integrate import quad
        lo, hi = dist.support
        for k in range(6):
            val, _ = quad(lambda a: a**k * dist.pdf(a), lo, hi, epsabs=0, epsrel=1e-12)
            assert dist.moment(k) == pytest.approx(val, rel=1e-9)


@pytest.mark.parametrize("dist", [uniform_size(4), uniform_volume(10), PowerLaw(3, -2), LogNormal(0.3)])
def test_systematic_sampling_reproduces_moments(dist):
    # stratified sampling error of <a^k> is O(1/N^2) for bounded smooth pdfs; lognormal tails
    # converge more slowly (quantile 1 - 1/(2N) is the largest reached), hence 1e-3 at N = 1e5
    radii = dist.sample(100_000)
    tol = 1e-3 if isinstance(dist, LogNormal) else 1e-6
    for k in range(6):
        assert np.mean(radii**k) == pytest.approx(dist.moment(k), rel=tol)


def test_small_systems_still_contain_the_largest_sizes():
    """Systematic sampling always fills the top stratum: max radius >= F^-1(1 - 1/N).

    Independent random sampling misses that stratum with probability (1 - 1/N)^N ~ 0.37.
    """
    dist = uniform_volume(50)
    n = 100
    for seed in range(20):
        radii = dist.sample(n, np.random.default_rng(seed))
        assert radii.max() >= dist.ppf(1 - 1 / n)
        assert radii.min() <= dist.ppf(1 / n)
    assert dist.sample(n).max() == pytest.approx(dist.ppf(1 - 0.5 / n))


def test_discrete_sampling_counts_exact():
    radii = bidisperse(1.4, 0.3).sample(1000, np.random.default_rng(1))
    assert np.sum(radii > 1) == 300
    assert radii.max() / radii.min() == pytest.approx(1.4)


def test_seeded_sampling_reproducible():
    a = uniform_size(3).sample(50, np.random.default_rng(7))
    b = uniform_size(3).sample(50, np.random.default_rng(7))
    c = uniform_size(3).sample(50, np.random.default_rng(8))
    assert np.array_equal(a, b) and not np.array_equal(a, c)


@pytest.mark.parametrize(
    "spec, message",
    [({"kind": "gaussian"}, "unknown distribution kind 'gaussian'"),
     ({"kind": "uniform_size"}, r"needs key\(s\) \['omega'\]"),
     ({"kind": "uniform_size", "omega": 2, "sigma": 1}, r"does not take key\(s\) \['sigma'\]"),
     ({"kind": "uniform_size", "omega": 0.5}, "omega = a_max / a_min must be > 1"),
     ({"kind": "lognormal", "sigma": -1}, "sigma must be positive"),
     ({"kind": "bidisperse", "size_ratio": 0.5, "large_fraction": 0.5}, "size_ratio must be >= 1"),
     ({"kind": "discrete", "radii": [1, 2], "fractions": [0.5, 0.6]}, "sum to 1"),
     ("uniform", "must be a mapping")],
)
def test_bad_specs_refused(spec, message):
    with pytest.raises(InvalidInputError, match=message):
        from_spec(spec)


def test_from_spec_builds_the_right_objects():
    assert from_spec({"kind": "monodisperse"}).radii == (1.0,)
    assert from_spec({"kind": "uniform_size", "omega": 1}).radii == (1.0,)
    assert isinstance(from_spec({"kind": "power_law", "omega": 3, "alpha": -2}), PowerLaw)
    assert from_spec({"kind": "discrete", "radii": [2, 1], "fractions": [0.25, 0.75]}).radii == (1.0, 2.0)
    assert monodisperse(2.0).moment(3) == 8.0
