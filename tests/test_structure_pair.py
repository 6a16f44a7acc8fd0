"""g2(r), Z(l) and the near-contact power-law fit (hardpack.structure.pair).

Noise levels: for N ideal-gas points in a periodic cell every distinct pair has exactly
v_shell / V expected images in a shell, and shell indicators of different pairs are pairwise
independent, so a bin's count has variance ~ its expected count E (relative noise 1/sqrt(E)).
The chi-square sum_bins (n - E)^2 / E over B bins then has mean B and sd sqrt(2B); we accept
|chi2/B - 1| < 5 sqrt(2/B).
"""

import itertools
import math

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.structure.pair import (
    cumulative_coordination,
    fit_coordination_power_law,
    fit_power_law,
    pair_correlation,
)


def chi2_ok(counts, expected):
    sel = expected > 20
    b = int(sel.sum())
    chi2 = float(np.sum((counts[sel] - expected[sel]) ** 2 / expected[sel]))
    return abs(chi2 / b - 1) < 5 * math.sqrt(2 / b), chi2 / b


@pytest.mark.parametrize("d, n, length", [(2, 3000, 30.0), (3, 3000, 10.0), (4, 2000, 5.0)])
def test_ideal_gas_g2_is_one_within_counting_noise(d, n, length, ideal_gas):
    ds = pair_correlation(ideal_gas(n, d, length), r_max=0.45 * length, dr=0.02 * length)
    ok, ratio = chi2_ok(ds.pair_count.values, ds.ideal_count.values)
    assert ok, f"chi2/dof = {ratio:.3f} for g2 of the ideal gas in d = {d}"
    total = ds.pair_count.values.sum()
    assert abs(total / ds.ideal_count.values.sum() - 1) < 5 / math.sqrt(total)


def test_ideal_gas_scaled_g2_polydisperse_is_one(ideal_gas):
    """g2 in x = r / (r_i + r_j): ideal count uses sum_{i<j} (r_i + r_j)^d (exact binomial sum)."""
    rng = np.random.default_rng(3)
    radii = rng.uniform(0.05, 0.4, 3000)
    ds = pair_correlation(ideal_gas(3000, 3, 10.0, radii, seed=4), r_max=1.0, x_max=6.0, dx=0.2)
    ok, ratio = chi2_ok(ds.pair_count_scaled.values, ds.ideal_count_scaled.values)
    assert ok, f"chi2/dof = {ratio:.3f}"


@pytest.mark.parametrize("self_images", [False, True])
def test_histogram_matches_independent_pair_search_in_small_sheared_cell(self_images):
    """Range beyond the cell: every periodic image, cross-checked with a brute-force loop over the
    pairs and lattice images (an independent implementation)."""
    rng = np.random.default_rng(7)
    lat = np.array([[2.0, 0.7, -0.3], [0.0, 1.8, 0.4], [0.0, 0.0, 2.2]])
    pos = rng.random((7, 3)) @ lat.T
    p = Packing(pos, np.full(7, 0.05), lat)
    r_max, dr = 3.9, 0.3  # no lattice-vector length on a bin edge (round-off would split it)
    ds = pair_correlation(p, r_max=r_max, dr=dr, x_max=30.0, dx=1.0, self_images=self_images,
                          contact_tol=0.0)
    x = p.fractional() @ lat.T
    images = np.array(list(itertools.product(range(-4, 5), repeat=3))) @ lat.T  # |n_k| <= r_max / h_k + 1
    dist = np.linalg.norm(x[None, :, None, :] + images[None, None, :, :] - x[:, None, None, :], axis=3)
    i, j, _ = np.nonzero((dist > 0) & (dist < r_max))
    found = dist[(dist > 0) & (dist < r_max)]
    keep = (i != j) | self_images
    # every unordered pair is seen twice (i, j, n) and (j, i, -n): half of each bin's count
    ref = np.bincount((found[keep] / dr).astype(int), minlength=len(ds.r))[: len(ds.r)] // 2
    np.testing.assert_array_equal(ds.pair_count.values, ref)
    n = p.n_particles
    norm = n * n / 2 if self_images else n * (n - 1) / 2
    shell = 4 / 3 * np.pi * ((ds.r.values + dr / 2) ** 3 - (ds.r.values - dr / 2) ** 3)
    np.testing.assert_allclose(ds.ideal_count.values, norm * shell / p.volume, rtol=1e-12)


def test_fcc_contacts_are_a_separate_delta_peak_and_second_shell_is_exact():
    p = lattice_packing("fcc", 4)  # N = 256, nearest neighbours touch at r = 1
    n = p.n_particles
    ds = pair_correlation(p, r_max=2.0, dr=0.01)
    assert ds.n_contacts == 6 * n and ds.z_contacts == 12.0
    bin_sqrt2 = int(np.sqrt(2) / 0.01)
    assert ds.pair_count.values[bin_sqrt2] == 3 * n  # 6 second neighbours per particle
    assert ds.pair_count.values[: bin_sqrt2].sum() == 0  # contacts are not in the histogram


def test_cumulative_coordination_fcc_with_and_without_a_rattler():
    p = lattice_packing("fcc", 3)
    n = p.n_particles
    mask = np.zeros(n, bool)
    mask[5] = True
    z = cumulative_coordination(p, gap_max=0.6, rattlers=mask)
    # contacts have round-off gaps of ~1e-16; the second shell sits at gap sqrt(2) - 1
    plateau = (z.gap.values > 1e-13) & (z.gap.values < np.sqrt(2) - 1 - 1e-9)
    assert np.all(z.Z_all.values[plateau] == 12.0)
    assert z.Z_all.values[-1] == 18.0
    # 12 bonds touch the rattler: backbone bonds 6N - 12 over N - 1 particles
    np.testing.assert_allclose(z.Z_backbone.values[plateau], 2 * (6 * n - 12) / (n - 1), rtol=1e-14)
    assert z.z_contacts_all == 12.0


def test_power_law_fit_recovers_exponent_amplitude_and_error():
    """Synthetic gaps: contacts at ~1e-13 plus a background Z = Zc + a l^alpha (alpha = 0.6,
    a = 11, Donev ch. 9); the fit must find alpha and a within their errors, and the Fisher
    error must match the scatter over independent samples (pull sd within 0.7..1.4)."""
    alpha, a, n, lo, hi = 0.6, 11.0, 4000, 1e-6, 0.1
    n_bg = round(n / 2 * a * (hi**alpha - lo**alpha))
    pulls = []
    for seed in range(30):
        rng = np.random.default_rng(seed)
        u = rng.random(n_bg)
        background = (lo**alpha + u * (hi**alpha - lo**alpha)) ** (1 / alpha)
        below = round(n / 2 * a * lo**alpha)
        gaps = np.concatenate([rng.uniform(0, 1e-13, 3 * n), rng.uniform(1e-12, lo, below),
                               background])
        fit = fit_power_law(gaps, n, lo, hi)
        pulls.append((fit.alpha - alpha) / fit.alpha_err)
        assert abs(fit.amplitude - a) < 5 * fit.amplitude_err
        assert abs(fit.z_contact - 6.0) < 0.1
    pulls = np.array(pulls)
    assert abs(pulls.mean()) < 5 / math.sqrt(len(pulls))
    assert 0.7 < pulls.std() < 1.4


def test_coordination_fit_on_dataset_uses_backbone_and_checks_window():
    p = lattice_packing("fcc", 3)
    z = cumulative_coordination(p, gap_max=0.5)
    with pytest.raises(InvalidInputError):
        fit_coordination_power_law(z, 1e-3, 1.0)  # beyond the stored gap range
    with pytest.raises(InvalidInputError):
        fit_coordination_power_law(z, 1e-3, 0.3)  # no gaps in the window for a crystal


@pytest.mark.parametrize("kwargs", [dict(r_max=-1.0), dict(dr=0.0), dict(contact_tol=-1.0),
                                    dict(r_max=1e9, dr=1e-3)])
def test_pair_correlation_refuses_bad_input(kwargs):
    with pytest.raises(InvalidInputError):
        pair_correlation(lattice_packing("sc", 2), **kwargs)


def test_rattler_mask_is_validated():
    p = lattice_packing("sc", 2)
    with pytest.raises(InvalidInputError):
        cumulative_coordination(p, rattlers=np.zeros(3, bool))
    with pytest.raises(InvalidInputError):
        cumulative_coordination(p, rattlers=np.zeros(p.n_particles, int))
    with pytest.raises(InvalidInputError):
        cumulative_coordination(p, rattlers=np.ones(p.n_particles, bool))
