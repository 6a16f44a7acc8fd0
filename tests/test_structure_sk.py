"""S(k), S(0) extrapolation and the number variance (hardpack.structure.sk).

Noise levels: for N independent uniform points and an allowed k != 0, E[S(k)] = 1 exactly and
S(k) is (for large N) exponentially distributed with variance 1, so a mean over m vectors has
standard error 1/sqrt(m); we accept deviations below 5 standard errors.
"""

import itertools
import math

import numpy as np
import pytest
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.structure.sk import (
    extrapolate_s0,
    number_variance,
    structure_factor,
    structure_factor_vectors,
    wavevectors,
)


def test_ideal_gas_structure_factor_is_one_and_exponential(ideal_gas):
    _, _, s = structure_factor_vectors(ideal_gas(3000, 3, 12.0), 12.0)
    m = s.size
    assert m > 5000
    assert abs(s.mean() - 1) < 5 / math.sqrt(m)
    # exponential law: P(S > 3) = e^-3, binomial error
    frac = np.mean(s > 3)
    assert abs(frac - math.exp(-3)) < 5 * math.sqrt(math.exp(-3) * (1 - math.exp(-3)) / m)


def test_ideal_gas_shell_means_scatter_as_counting_noise(ideal_gas):
    sk = structure_factor(ideal_gas(2000, 3, 10.0, seed=1), 15.0)
    z = (sk.S.values - 1) * np.sqrt(sk.n_vectors.values)
    assert abs(np.mean(z**2) - 1) < 5 * math.sqrt(2 / len(z))


@pytest.mark.parametrize("name, reps", [("sc", 6), ("square", 7), ("fcc", 3), ("hypercubic4", 3)])
def test_perfect_lattice_bragg_peaks(name, reps):
    """S = 0 off the Bragg peaks and N on them (N |F|^2 / n_b^2 with the basis: FCC in its cubic
    cell has n_b = 4 and F = 4 for Miller indices all even or all odd, else 0)."""
    p = lattice_packing(name, reps)
    n, _, s = structure_factor_vectors(p, 2 * np.pi * 2.2)
    n_part = p.n_particles
    hkl = n / reps  # Miller indices of the conventional cell where integer
    on_lattice = np.all(np.abs(hkl - np.round(hkl)) < 1e-12, axis=1)
    if name == "fcc":
        par = np.mod(np.round(hkl).astype(int), 2)
        on_lattice &= np.all(par == par[:, :1], axis=1)
    assert on_lattice.any()
    np.testing.assert_allclose(s[on_lattice], n_part, rtol=1e-12)
    assert s[~on_lattice].max() < 1e-18 * n_part


@pytest.mark.parametrize("lattice", [
    np.array([[2.5]]),
    np.array([[3.0, 1.0], [0.4, 2.0]]),
    np.array([[3.0, 0.5, 0.2], [0.0, 2.5, -0.4], [0.0, 0.0, 2.8]]),
    np.diag([2.0, 3.0, 2.5, 2.2]) + 0.3 * np.triu(np.ones((4, 4)), 1),
])
def test_direct_sum_and_wavevectors_match_brute_force(lattice):
    d = len(lattice)
    rng = np.random.default_rng(d)
    p = Packing(rng.random((40, d)) @ lattice.T, np.full(40, 1e-3), lattice, allow_overlap=True)
    k_max = 7.0
    n, k, s = structure_factor_vectors(p, k_max)
    # brute-force enumeration of the allowed wavevectors (one of each +-n pair)
    lim = np.ceil(k_max * np.linalg.norm(lattice, axis=0) / (2 * np.pi)).astype(int) + 1
    cand = np.array(list(itertools.product(*[range(-m, m + 1) for m in lim])))
    kc = 2 * np.pi * cand @ np.linalg.inv(lattice)
    inside = (np.linalg.norm(kc, axis=1) <= k_max) & cand.any(axis=1)
    assert len(n) == inside.sum() // 2
    keys = {tuple(v) for v in n.tolist()}
    assert not any(tuple(v) in keys for v in (-n).tolist())  # never both n and -n
    np.testing.assert_allclose(k, 2 * np.pi * n @ np.linalg.inv(lattice), atol=1e-12)
    rho = np.exp(-1j * p.positions @ k.T).sum(axis=0)
    np.testing.assert_allclose(s, np.abs(rho) ** 2 / p.n_particles, atol=1e-10)


def test_wavevectors_refuse_bad_k_max():
    for bad in (0.0, -1.0, np.nan, None):
        with pytest.raises(InvalidInputError):
            wavevectors(np.eye(3), bad)


def test_s0_extrapolation_recovers_known_line_and_ideal_gas(ideal_gas):
    k = np.linspace(0.2, 2.0, 12)
    exact = xr.Dataset(dict(S=("k", 0.01 + 0.05 * k), n_vectors=("k", np.full(12, 30))),
                       coords=dict(k=k))
    s0, err, coef = extrapolate_s0(exact, 1.5, "linear")
    assert abs(s0 - 0.01) < 1e-12 and abs(coef[1] - 0.05) < 1e-12
    quad = exact.assign(S=("k", 0.02 + 0.004 * k**2))
    assert abs(extrapolate_s0(quad, 2.0, "quadratic")[0] - 0.02) < 1e-12
    sk = structure_factor(ideal_gas(3000, 3, 14.0, seed=2), 3.0)
    s0, err, _ = extrapolate_s0(sk, 3.0)
    assert abs(s0 - 1) < 5 * err and err < 0.3
    with pytest.raises(InvalidInputError):
        extrapolate_s0(sk, 0.1)
    with pytest.raises(InvalidInputError):
        extrapolate_s0(sk, 3.0, "cubic")


def test_number_variance_ideal_gas_is_binomial(ideal_gas):
    """Averaged over configurations the window count of the ideal gas is binomial,
    sigma^2 = N p (1 - p). One configuration's variance also fluctuates (through S(k) at
    k < ~pi/R), so the error bar is the spread over 8 independent configurations."""
    radii = np.array([0.5, 1.0, 1.5, 2.0])
    runs = np.array([number_variance(ideal_gas(2000, 3, 12.6, seed=s), radii, n_windows=2000,
                                     seed=s).variance.values for s in range(8)])
    frac = 4 / 3 * np.pi * radii**3 / 12.6**3
    binomial = 2000 * frac * (1 - frac)
    err = runs.std(axis=0, ddof=1) / math.sqrt(len(runs))
    assert np.all(np.abs(runs.mean(axis=0) - binomial) < 5 * err)
    assert np.all(err < 0.1 * binomial)  # the test resolves 10 % deviations


def test_number_variance_of_1d_lattice_is_exact():
    """Unit-spaced 1D lattice, window length 2R at a uniform random position: the count is
    floor(2R) or floor(2R) + 1, so the variance is f (1 - f) with f = frac(2R) (hyperuniform:
    bounded, not growing like R)."""
    p = lattice_packing("hypercubic1", 40)
    radii = np.array([0.3, 1.15, 2.4, 5.05, 9.7])
    nv = number_variance(p, radii, n_windows=20000, seed=3)
    f = np.mod(2 * radii, 1)
    np.testing.assert_allclose(nv["mean"], 2 * radii, atol=5 * 0.5 / math.sqrt(20000))
    assert np.all(np.abs(nv.variance - f * (1 - f)) < 5 * nv.variance_err + 1e-12)


def test_number_variance_refuses_bad_input():
    p = lattice_packing("sc", 2)
    with pytest.raises(InvalidInputError):
        number_variance(p, [-1.0])
    with pytest.raises(InvalidInputError):
        number_variance(p, [1.0], n_windows=1)
