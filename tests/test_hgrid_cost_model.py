"""Analytic HGrid cost model vs Ogarko 2014, sec. 2.2 (Eqs. 2.14-2.47, Figs. 2.9-2.15)."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from hardpack.errors import InvalidInputError
from hardpack.hgrid import cost_model as cm

FIG_215 = cm.PowerLawSystem(alpha=-3.0, omega=100.0, nu=0.7, d=3)  # K = 0.2, Top-Down (Ogarko 2014, Fig. 2.15)


def brute_force_cost(system, s, K, method):
    """Eqs. 2.17-2.35 evaluated literally with numerical quadrature (independent of the closed forms)."""
    lo_r, hi_r = 1.0, system.omega
    C = 1 / quad(lambda r: r**system.alpha, lo_r, hi_r)[0]

    def f(r):
        return C * r**system.alpha

    def integral(g, a, b):
        a, b = max(a, lo_r), min(b, hi_r)
        return quad(lambda r: g(r) * f(r), a, b, epsabs=0, epsrel=1e-12)[0] if b > a else 0.0

    d, nc, L = system.d, (3**system.d - 1) / 2, len(s) - 1
    vp = math.pi ** (d / 2) / math.gamma(d / 2 + 1) * integral(lambda r: r**d, lo_r, hi_r)
    p = [integral(lambda r: 1.0, s[h] / 2, s[h + 1] / 2) for h in range(L)]
    m = [system.nu * s[h + 1] ** d * p[h] / vp for h in range(L)]
    total = 0.0
    for h in range(L):
        if p[h] == 0:
            continue
        others = range(h) if method == "top-down" else range(h + 1, L)
        b = {j: integral(lambda r, j=j: (2 * r / s[j + 1] + 2) ** d, s[h] / 2, s[h + 1] / 2) / p[h] for j in others}
        tcd = (0.5 + nc) * m[h] + sum(m[j] * b[j] for j in others)
        tca = 1 + nc + sum(b.values())
        total += p[h] * (tcd + K * tca)
    return total


@pytest.mark.parametrize("method", cm.METHODS)
@pytest.mark.parametrize(
    "system, cells",
    [
        (cm.PowerLawSystem(-2.0, 10.0, 0.5, 3), cm.exponential_cells(3, 10.0)),
        (cm.PowerLawSystem(0.0, 5.0, 0.7, 2), cm.linear_cells(4, 5.0)),
        (cm.PowerLawSystem(-1.0, 20.0, 0.6, 3), np.array([2.0, 2.5, 9.0, 9.0, 40.0])),  # includes an empty level
    ],
    ids=["a-2_exp3", "2D_a0_lin4", "a-1_custom"],
)
def test_cost_matches_literal_equations(system, cells, method):
    assert system.cost(cells, 0.2, method) == pytest.approx(brute_force_cost(system, cells, 0.2, method), rel=1e-9)


def test_linked_cell_values():
    """Single level (Eqs. 2.39-2.40): alpha = -3, omega = 100 -> 91146; monodisperse nu = 0.7 -> 20.85;
    alpha = 0, omega -> infinity -> 75.0 (values of an independent re-implementation of the model; not
    printed in Ogarko 2014)."""
    assert FIG_215.linked_cell_cost(0.2) == pytest.approx(91146, abs=0.5)
    assert FIG_215.cost([2.0, 200.0]) == pytest.approx(FIG_215.linked_cell_cost(0.2), rel=1e-12)
    assert cm.PowerLawSystem(0.0, 1.0).linked_cell_cost(0.2) == pytest.approx(20.85, abs=5e-3)
    # alpha = 0: m_1 -> 2^d nu/V_d (1 + d) = 5.348, T/N -> 13.5 m_1 + 0.2 * 14 = 75.0
    assert cm.PowerLawSystem(0.0, 1e9).linked_cell_cost(0.2) == pytest.approx(75.0, abs=0.05)


@pytest.mark.parametrize("alpha", [0.0, -1.0, -2.0, -3.0, -4.0, -5.5])
def test_linked_cell_closed_form(alpha):
    """Eq. 2.40 (incl. the alpha = -1 and alpha = -1-d limits) equals the definition Eq. 2.39 by quadrature."""
    sys = cm.PowerLawSystem(alpha, 30.0, 0.6, 3)
    num = quad(lambda r: r**alpha, 1, 30)[0] / quad(lambda r: r ** (alpha + 3), 1, 30)[0]
    assert sys.linked_cell_m() == pytest.approx(60.0**3 * 0.6 / (4 * math.pi / 3) * num, rel=1e-10)


@pytest.mark.parametrize("alpha, power", [(0.0, 0.0), (-2.0, 1.0), (-5.0, 3.0)])
def test_linked_cell_asymptotics(alpha, power):
    """Eq. 2.41 (with the misprinted limit alpha -> inf read as omega -> inf): m_1 tends to a constant for
    alpha > -1, grows like omega^(-1-alpha) for -1-d < alpha < -1 and like omega^d for alpha < -1-d, with
    prefactor |2^d nu/V_d (1+d+alpha)/(1+alpha)|."""
    omega = 1e7
    m1 = cm.PowerLawSystem(alpha, omega).linked_cell_m()
    pref = abs(8 * 0.7 / (4 * math.pi / 3) * (4 + alpha) / (1 + alpha))
    assert m1 / omega**power == pytest.approx(pref, rel=1e-5)


def test_figure_2_15_minima():
    """alpha = -3, omega = 100, nu = 0.7, d = 3, K = 0.2, Top-Down (Ogarko 2014, sec. 2.2.5, Fig. 2.15): linear 12.40 at L* = 43,
    constant-m 11.60 at L* = 12 (our 12.398 and 11.595), optimal 11.58; L = 8 and 19 cost 10 % more than
    the constant-m optimum; exponential L* = 4 with L = 6 24 % worse.

    The printed exponential numbers that our model does not reproduce (the minimum 11.57, below the
    printed optimum 11.58, and "L = 3 is 43 % worse") are tested in
    test_figure_2_15_printed_exponential_minimum, an expected failure."""
    L_lin, t_lin, _ = cm.best_levels(FIG_215, "linear", L_max=60)
    assert (L_lin, round(t_lin, 2)) == (43, 12.40)
    levels = np.arange(1, 31)
    const_m = cm.cost_vs_levels(FIG_215, "constant-m", levels)
    assert levels[np.argmin(const_m)] == 12 and round(const_m.min(), 2) == 11.60
    assert const_m[7] / const_m[11] == pytest.approx(1.10, abs=0.005)
    assert const_m[18] / const_m[11] == pytest.approx(1.10, abs=0.005)
    expo = cm.cost_vs_levels(FIG_215, "exponential", levels)
    assert levels[np.argmin(expo)] == 4
    assert expo[5] / expo[3] == pytest.approx(1.24, abs=0.005)  # printed: L = 6 is 24 % worse


@pytest.mark.xfail(strict=True, reason=(
    "Ogarko Fig. 2.15 prints 11.57 for the exponential minimum, below the printed optimum 11.58: "
    "impossible for one cost model (the optimum bounds every rule). With the stated parameters our "
    "model gives 12.13 at L = 4, and 47 % (printed 43 %) for L = 3; the printed exponential curve "
    "does not follow from the stated parameters."))
def test_figure_2_15_printed_exponential_minimum():
    levels = np.arange(1, 31)
    expo = cm.cost_vs_levels(FIG_215, "exponential", levels)
    assert round(expo.min(), 2) == 11.57
    assert expo[2] / expo[3] == pytest.approx(1.43, abs=0.005)


def test_figure_2_15_optimal():
    """The optimised cell sizes never lose to constant-m at equal L, and reach at least the printed
    optimum 11.58 (a lower cost is a better optimum of the same model; ours is 11.574, a documented
    deviation of the validation table)."""
    costs = []
    for L in (6, 8, 10):
        opt = FIG_215.cost(cm.optimal_cells(FIG_215, L))
        assert opt <= FIG_215.cost(cm.constant_m_cells(FIG_215, L)) + 1e-9
        costs.append(opt)
    assert min(costs) <= 11.58 + 0.005


def test_constant_m_cells():
    """Eqs. 2.45-2.47: q = 1 gives equal m_h at every level, q = 2 doubles m from level to level."""
    for q in (1.0, 2.0):
        s = cm.constant_m_cells(FIG_215, 7, q)
        _, m = FIG_215.occupancy(s)
        assert m[1:] / m[:-1] == pytest.approx(q, rel=1e-9)
        assert s[0] == 2 and s[-1] == 200 and np.all(np.diff(s) > 0)


def test_q_between_one_and_two():
    """Fig. 2.12 inset: the best q lies between 1 and 2 and q = 1 is within 0.5 % of it."""
    levels = range(1, 31)
    best = {
        q: min(FIG_215.cost(cm.constant_m_cells(FIG_215, L, q)) for L in levels) for q in (0.9, 1.0, 1.1, 1.3, 2.0, 5.0)
    }
    inside = min(best[q] for q in (1.1, 1.3))
    assert inside < best[0.9] and inside < best[2.0] and inside < best[5.0]
    assert best[1.0] < 1.005 * inside


@pytest.mark.parametrize(
    "alpha, omega, expected",
    [
        (0.0, 2.0, 28.4),
        (0.0, 100.0, 29.5),
        (-2.0, 10.0, 22.7),
        (-2.0, 100.0, 13.6),
        (-3.0, 10.0, 20.5),
        (-3.0, 100.0, 11.6),
    ],
)
def test_constant_m_optima_below_30(alpha, omega, expected):
    """T <= 30 N in 3D (Ogarko 2014, sec. 2.2.6) at the constant-m optimum; the values are those of an
    independent re-implementation of the model (not printed in the work). The alpha = 0 optimum for large
    omega is ~60 % below the linked-cell 75.0 (sec. 2.2.5, text on Figs. 2.9-2.10)."""
    _, t, _ = cm.best_levels(cm.PowerLawSystem(alpha, omega), "constant-m", L_max=30)
    assert t == pytest.approx(expected, abs=0.05) and t <= 30


def test_top_down_vs_bottom_up():
    """Top-Down is preferred for alpha < 0 and always with constant m; Bottom-Up wins for alpha >= 0 with
    linear and exponential cells (Ogarko 2014, sec. 2.2.5, text on Figs. 2.10, 2.11 and 2.13)."""
    for alpha in (-2.0, -3.0):
        sys = cm.PowerLawSystem(alpha, 100.0)
        for rule in ("exponential", "constant-m"):
            assert cm.best_levels(sys, rule, 30)[1] < cm.best_levels(sys, rule, 30, method="bottom-up")[1]
    sys0 = cm.PowerLawSystem(0.0, 100.0)
    assert cm.best_levels(sys0, "constant-m", 30)[1] < cm.best_levels(sys0, "constant-m", 30, method="bottom-up")[1]
    for rule in ("linear", "exponential"):
        assert cm.best_levels(sys0, rule, 30, method="bottom-up")[1] < cm.best_levels(sys0, rule, 30)[1]


def test_refusals():
    with pytest.raises(InvalidInputError):
        FIG_215.cost([2.0, 50.0])  # does not end at 2 r_max
    with pytest.raises(InvalidInputError):
        FIG_215.cost([2.0, 80.0, 40.0, 200.0])  # decreasing
    with pytest.raises(InvalidInputError):
        FIG_215.cost([2.0, 200.0], method="sideways")
    with pytest.raises(InvalidInputError):
        cm.PowerLawSystem(-3.0, 0.5)
    with pytest.raises(InvalidInputError):
        cm.PowerLawSystem(-3.0, 10.0, nu=1.2)
    with pytest.raises(InvalidInputError):
        cm.cells_for(FIG_215, "random", 3)
    with pytest.raises(InvalidInputError):
        cm.linear_cells(0, 10.0)
