"""Moments and equivalent mixtures vs Ogarko's Tables 3.1, 3.3, 3.4 (the validation targets) and closed forms."""

import math

import mpmath
import numpy as np
import pytest

from hardpack.distributions import Discrete, LogNormal, bidisperse, monodisperse, uniform_size, uniform_volume
from hardpack.eos import moments as mo
from hardpack.errors import InvalidInputError
from hardpack.validation.analytic import moment_table_rows

OMEGAS_31 = (1.2, 1.4, 2, 4, 5, 7, 8, 10, 20, 50, 100)
#: the printed cells our values do not round to (Table 3.3 omega = 4 n2 and delta1; Table 3.4
#: sigma = 0.15 n1, 0.5 delta2, 1.0 n2): each lies 0.51-0.77 units of the last digit below ours
KNOWN_MISPRINTS = {"ogarko-t3.3-uv-omega4-n2", "ogarko-t3.3-uv-omega4-delta1", "ogarko-t3.4-ln-sigma0.15-n1",
                   "ogarko-t3.4-ln-sigma0.5-delta2", "ogarko-t3.4-ln-sigma1.0-n2"}


def test_every_printed_cell_of_tables_31_33_34_rounds_to_ours_but_the_known_misprints():
    rows = moment_table_rows()
    assert len(rows) == 9 * 4 + 9 * 5 + 7 * 4 + 20 * 4  # one row per printed cell
    assert {r.target for r in rows if r.status != "pass"} == KNOWN_MISPRINTS
    for r in rows:
        if r.target in KNOWN_MISPRINTS:
            units = (r.reproduced - r.published) / (2 * r.tolerance)
            assert 0.5 < units < 0.8 and r.status == "known deviation", (r.target, units)
    # the table rounds: many of its cells lie below our values, so truncation does not explain the five
    tri = [r for r in rows if r.target.startswith(("ogarko-t3.3", "ogarko-t3.4"))]
    assert sum(r.reproduced < r.published for r in tri) == 42


def test_uniform_size_bidisperse_equivalent_is_equimolar():
    for omega in OMEGAS_31:
        assert mo.equivalent_bidisperse(uniform_size(omega)).n1 == pytest.approx(0.5, abs=1e-9)


def test_independent_high_precision_tridisperse_solve_agrees():
    """The five misprinted cells, recomputed with 50-digit Gauss quadrature from the exact moments
    (an independent route to the 3-node equivalent), agree with ours to 1e-10."""
    mpmath.mp.dps = 50
    for family, x, name in (("UV", 4, "n2"), ("UV", 4, "delta1"), ("LN", 0.15, "n1"), ("LN", 0.5, "delta2"),
                            ("LN", 1.0, "n2")):
        dist = uniform_volume(x) if family == "UV" else LogNormal(x)
        ours = getattr(mo.equivalent_tridisperse(dist), name)
        ref = _gauss_equivalent(mpmath, family, x)[name]
        assert float(ref) == pytest.approx(ours, rel=1e-10), (family, x, name)


def _gauss_equivalent(mp, family, x):
    """The 3-node Gauss rule of the radius distribution, computed in 50 digits from its exact raw
    moments M_0..M_5 (monic orthogonal polynomial from the Hankel system, nodes by polyroots,
    weights by a Vandermonde solve), in Ogarko's conventions: number fractions n_i of the radii
    a_1 > a_2 > a_3 and delta_i = n_i a_i / <a>."""
    if family == "UV":
        w = mp.mpf(x)
        norm = (1 - w**-2) / 2  # f(a) ~ a^-3 on [1, w]
        moments = [((w ** (k - 2) - 1) / (k - 2) if k != 2 else mp.log(w)) / norm for k in range(6)]
    else:
        s = mp.mpf(x)
        moments = [mp.e ** (k * k * s * s / 2) for k in range(6)]
    a = mp.matrix([[moments[i + j] for j in range(3)] for i in range(3)])
    c = mp.lu_solve(a, mp.matrix([-moments[i + 3] for i in range(3)]))
    nodes = sorted((mp.re(r) for r in mp.polyroots([1, c[2], c[1], c[0]], maxsteps=200, extraprec=200)),
                   reverse=True)
    v = mp.matrix([[node**k for node in nodes] for k in range(3)])
    weights = mp.lu_solve(v, mp.matrix(moments[:3]))
    mean = moments[1]
    return {"n1": weights[0], "n2": weights[1], "delta1": weights[0] * nodes[0] / mean,
            "delta2": weights[1] * nodes[1] / mean}


@pytest.mark.parametrize("omega", OMEGAS_31)
def test_closed_form_equivalent_matches_quadrature(omega):
    """Eqs. 3.20-3.21 (closed form from O1, O2) = 2-node Gauss quadrature, and back-substitution."""
    for dist in (uniform_size(omega), uniform_volume(omega)):
        eq = mo.equivalent_bidisperse(dist)
        n1, R = mo.bidisperse_from_O(*mo.dimensionless_moments(dist))
        assert n1 == pytest.approx(eq.n1, abs=1e-9) and R == pytest.approx(eq.R, rel=1e-9)
        assert mo.dimensionless_moments(eq.mixture) == pytest.approx(mo.dimensionless_moments(dist), rel=1e-12)
        assert mo.raw_moments(eq.mixture, 3) == pytest.approx(mo.raw_moments(dist, 3), rel=1e-11)


def test_table_31_limits():
    """Rows omega = 1 (monodisperse) and omega = infinity (US: 2/3, 16/27, 2 + sqrt 3, sqrt(3)/3; UV: 0, 0)."""
    mono = monodisperse(1.3)
    assert mo.dimensionless_moments(mono) == pytest.approx((1.0, 1.0), rel=1e-15)
    eq = mo.equivalent_bidisperse(mono)
    assert (eq.n1, eq.R, mo.polydispersity(mono)) == (0.5, 1.0, 0.0)
    assert mo.bidisperse_from_O(*mo.dimensionless_moments(mono)) == (0.5, 1.0)
    # O1, O2 and R approach their limits like 1/omega; delta like 1/omega as well
    big = uniform_size(1e7)
    O1, O2 = mo.dimensionless_moments(big)
    assert O1 == pytest.approx(2 / 3, abs=1e-6) and O2 == pytest.approx(16 / 27, abs=1e-6)
    assert mo.equivalent_bidisperse(big).R == pytest.approx(2 + math.sqrt(3), abs=1e-5)
    assert mo.polydispersity(big) == pytest.approx(math.sqrt(3) / 3, abs=1e-6)
    O1, O2 = mo.dimensionless_moments(uniform_volume(1e8))
    assert O1 < 1e-6 and O2 < 1e-11  # 2 ln(w)/w and 2 ln(w)^3/w^2


@pytest.mark.parametrize("omega", (2, 3, 4, 5, 6, 8, 10))
def test_uniform_volume_tridisperse_matches_five_moments(omega):
    eq = mo.equivalent_tridisperse(uniform_volume(omega))
    a = eq.radii
    assert a[0] > a[1] > a[2] > 0  # Ogarko's ordering a1 >= a2 >= a3
    assert mo.raw_moments(eq.mixture, 5) == pytest.approx(mo.raw_moments(uniform_volume(omega), 5), rel=1e-10)


def test_table_33_radii_example():
    """Note 002 sec. 4.6: omega = 10 gives radii (4.454, 1.911, 0.726) <a>."""
    assert mo.equivalent_tridisperse(uniform_volume(10)).radii == pytest.approx([4.454, 1.911, 0.726], abs=6e-4)


@pytest.mark.parametrize("sigma", (0.05, 0.5, 1.0))
def test_lognormal_tridisperse_matches_five_moments(sigma):
    # sigma = 1: M_5 = e^10, n1 ~ 1e-5; the moments are still matched to 1e-10
    eq = mo.equivalent_tridisperse(LogNormal(sigma))
    assert mo.raw_moments(eq.mixture, 5) == pytest.approx(mo.raw_moments(LogNormal(sigma), 5), rel=1e-10)


@pytest.mark.parametrize("sigma", [0.1, 0.5, 1.0])
def test_lognormal_dimensionless_moments(sigma):
    """Eq. 3.25: O1 = exp(-2 sigma^2), O2 = exp(-3 sigma^2); Eq. 3.54: exp(-2 sigma^2) = (D32/D43)^2;
    Eqs. 3.50-3.51 recover sigma and a0 from D32 and D43."""
    dist = LogNormal(sigma, mean_radius=2.5)
    O1, O2 = mo.dimensionless_moments(dist)
    assert O1 == pytest.approx(math.exp(-2 * sigma**2), rel=1e-13)
    assert O2 == pytest.approx(math.exp(-3 * sigma**2), rel=1e-13)
    d32, d43 = mo.mean_diameter(dist, 3, 2), mo.mean_diameter(dist, 4, 3)
    assert (d32 / d43) ** 2 == pytest.approx(O1, rel=1e-13)
    assert math.sqrt(math.log(d43 / d32)) == pytest.approx(sigma, rel=1e-12)
    assert 0.5 * math.sqrt(d32 * d43) * (d32 / d43) ** 3 == pytest.approx(dist.a0, rel=1e-12)
    assert mo.skewness(dist) == pytest.approx((math.exp(sigma**2) + 2) * math.sqrt(math.exp(sigma**2) - 1), rel=1e-9)


@pytest.mark.parametrize("omega", [1.2, 2.0, 3.0, 10.0, 100.0])
def test_uniform_size_tridisperse_is_585(omega):
    """US: 5:8:5 with radii <a>(1 +- omega0 sqrt(3/5)) and <a> (Ogarko 2014, Eqs. 3.39-3.40, sec. 3.2); the generic
    quadrature, the printed formula and the kurtosis family at beta2 = 1.8 coincide."""
    w0 = (omega - 1) / (omega + 1)
    dist = uniform_size(omega)
    quad = mo.equivalent_tridisperse(dist)
    formula = mo.tridisperse_uniform_size(omega)
    family = mo.kurtosis_family(omega, 1.8)
    for eq in (quad, formula, family):
        assert [eq.n1, eq.n2, 1 - eq.n1 - eq.n2] == pytest.approx([5 / 18, 8 / 18, 5 / 18], abs=1e-9)
        assert eq.radii == pytest.approx([1 + w0 * math.sqrt(0.6), 1.0, 1 - w0 * math.sqrt(0.6)], rel=1e-9)
        assert eq.delta1 == pytest.approx((5 + math.sqrt(15) * w0) / 18, rel=1e-9)
    # uniform size: skewness 0 and kurtosis 9/5
    assert mo.kurtosis(dist) == pytest.approx(1.8, rel=1e-9)
    assert mo.skewness(dist) == pytest.approx(0.0, abs=1e-7)
    # bidisperse equivalent of US: radii <a>(1 +- omega0/sqrt 3) with n1 = 1/2 (2-point Gauss-Legendre)
    bi = mo.equivalent_bidisperse(dist)
    assert bi.mixture.radii == pytest.approx([1 - w0 / math.sqrt(3), 1 + w0 / math.sqrt(3)], rel=1e-10)
    assert bi.n1 == pytest.approx(0.5, abs=1e-10)


@pytest.mark.parametrize("beta2", [1.2, 1.8, 3.0, 6.0, 11.0])
def test_kurtosis_family_omega_3(beta2):
    """Eqs. 3.41-3.42 (omega = 3) and their defining property: the central scaled moments M^c_2, M^c_3,
    M^c_5 of US(3) (1/12, 0, 0) with kurtosis beta2."""
    eq = mo.kurtosis_family(3.0, beta2)
    assert eq.n1 == pytest.approx(1 / (2 * beta2)) and eq.n2 == pytest.approx((beta2 - 1) / beta2)
    assert eq.delta1 == pytest.approx((6 + math.sqrt(3 * beta2)) / (12 * beta2), rel=1e-12)
    us = mo.central_scaled_moments(uniform_size(3.0), 5)
    fam = mo.central_scaled_moments(eq.mixture, 5)
    assert fam[[2, 3, 5]] == pytest.approx(us[[2, 3, 5]], rel=1e-12, abs=1e-14)
    assert us[2] == pytest.approx(1 / 12, rel=1e-12)
    assert mo.kurtosis(eq.mixture) == pytest.approx(beta2, rel=1e-12)


def test_kurtosis_family_bounds():
    with pytest.raises(InvalidInputError):
        mo.kurtosis_family(3.0, 12.0)  # smallest radius reaches 0 (Ogarko 2014, sec. 3.2)
    with pytest.raises(InvalidInputError):
        mo.kurtosis_family(3.0, 1.0)  # no middle species: that is a bidisperse system


def test_bidisperse_source_is_its_own_equivalent():
    mix = bidisperse(1.4, 0.3)
    eq = mo.equivalent_bidisperse(mix)
    assert eq.R == pytest.approx(1.4, rel=1e-12) and eq.n1 == pytest.approx(0.3, rel=1e-12)
    tri = Discrete((0.5, 1.0, 2.0), (0.2, 0.5, 0.3))
    eq3 = mo.equivalent_tridisperse(tri)
    assert eq3.radii == pytest.approx([2.0, 1.0, 0.5] / np.sum(np.array([0.5, 1, 2]) * [0.2, 0.5, 0.3]), rel=1e-9)
    assert [eq3.n1, eq3.n2] == pytest.approx([0.3, 0.5], rel=1e-9)
    with pytest.raises(InvalidInputError, match="fewer than 3 distinct radii"):
        mo.equivalent_tridisperse(mix)
    with pytest.raises(InvalidInputError, match="fewer than 2 distinct radii"):
        mo.gauss_quadrature(np.full(10, 0.7), 2)


@pytest.mark.parametrize(
    "dist",
    [uniform_size(4.0), uniform_volume(10.0), LogNormal(0.5), bidisperse(1.4, 0.5)],
    ids=["US4", "UV10", "LN0.5", "bi1.4"],
)
def test_moment_relations(dist):
    """delta = (O2/O1^2 - 1)^(1/2) (Ogarko 2014, appendix of sec. 3.1); 0 < O1 <= 1, O1^2 <= O2 <= O1 (sec. 3.1.2);
    kurtosis >= 1; M^c_k from raw moments vs direct definitions."""
    O1, O2 = mo.dimensionless_moments(dist)
    assert 0 < O1 < 1 and O1**2 < O2 < O1
    assert mo.polydispersity(dist) == pytest.approx(math.sqrt(O2 / O1**2 - 1), rel=1e-10)
    assert mo.kurtosis(dist) >= 1
    M = mo.scaled_moments(dist, 3)
    assert M[0] == 1 and M[1] == pytest.approx(1)
    assert mo.central_scaled_moments(dist, 3)[2:] == pytest.approx([M[2] - 1, M[3] - 3 * M[2] + 2], rel=1e-9)
    assert mo.mean_diameter(dist, 1, 0) == pytest.approx(2 * dist.moment(1))


@pytest.mark.parametrize(
    "dist, tol",
    [(uniform_size(4.0), 1e-8), (uniform_volume(10.0), 1e-6), (LogNormal(0.5), 2e-2)],
    ids=["US4", "UV10", "LN0.5"],
)
def test_sampled_moments_converge(dist, tol):
    """Systematic samples (Ogarko 2014, sec. 2.1.3) converge to the analytic moments: O(1/N^2) for bounded supports
    (midpoint rule on the quantile function), slower for the log-normal (the tail beyond the quantile
    1 - 1/2N is missing: 1.2 % in <a^5> for sigma = 0.5). Tolerances are for N = 10^5 and k <= 5."""
    exact = mo.raw_moments(dist, 5)
    errors = [np.max(np.abs(mo.raw_moments(dist.sample(n), 5) / exact - 1)) for n in (1000, 10_000, 100_000)]
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < tol


@pytest.mark.parametrize(
    "dist, tol, tol_bi", [(uniform_volume(4.0), 2e-3, 1e-4), (LogNormal(0.3), 3e-2, 1e-3)], ids=["UV4", "LN0.3"]
)
def test_equivalents_from_samples(dist, tol, tol_bi):
    """Equivalents built from 10^5 sampled radii agree with those from the analytic moments, and the
    agreement improves with N. The log-normal tolerance is wider: the sample misses the tail beyond
    the quantile 1 - 1/2N (<a^5> low by 4e-4 at N = 10^5), and the rare large species n1 ~ 0.03
    amplifies that about 50-fold (2 % at 10^5, 0.5 % at 10^6)."""
    ref = mo.equivalent_tridisperse(dist)
    ref_params = np.array([ref.n1, ref.n2, ref.delta1, ref.delta2])
    errors = []
    for n in (10_000, 100_000):
        tri = mo.equivalent_tridisperse(dist.sample(n, np.random.default_rng(1)))
        errors.append(np.max(np.abs(np.array([tri.n1, tri.n2, tri.delta1, tri.delta2]) / ref_params - 1)))
    assert errors[1] < errors[0] and errors[1] < tol
    radii = dist.sample(100_000, np.random.default_rng(1))
    bi_s, bi_a = mo.equivalent_bidisperse(radii), mo.equivalent_bidisperse(dist)
    assert (bi_s.n1, bi_s.R) == pytest.approx((bi_a.n1, bi_a.R), rel=tol_bi)


def test_bad_input_refused():
    for bad in ([], [1.0, -1.0], [1.0, np.nan], [[1.0, 2.0]]):
        with pytest.raises(InvalidInputError):
            mo.raw_moments(bad)
    with pytest.raises(InvalidInputError):
        mo.bidisperse_from_O(0.8, 0.9)  # O2 > O1 is impossible
    with pytest.raises(InvalidInputError):
        mo.mean_diameter(uniform_size(2.0), 3, 3)
    with pytest.raises(InvalidInputError):
        mo.gauss_quadrature(uniform_size(2.0), 0)
    assert math.isnan(mo.kurtosis(monodisperse()))
