"""Analytic cost model of hierarchical-grid (HGrid) contact detection (Ogarko 2014, sec. 2.2,
Eqs. 2.14-2.47; the section is based on Krijgsman, Ogarko & Luding, Comp. Part. Mech. 2014).

Model: N spheres in d dimensions at volume fraction nu, random positions without excluded volume,
radii i.i.d. from f(r) = C r^alpha on [r_min, omega r_min] (Eq. 2.37). Lengths are in units of r_min.
An HGrid has levels h = 1..L with cell sizes s_1 < ... < s_L and boundaries s_0 = 2 r_min,
s_L = 2 r_max (diameters: below Eq. 2.18 and Eq. 2.44; the text's "s_0 = r_min" below Eqs. 2.43 and
2.47 and in the optimal cell-size paragraph of sec. 2.2.5 is a typo).
A particle of radius r lives on level h if s_{h-1} < 2r <= s_h. Per level (Eqs. 2.17-2.19):

    p_h = int_{s_{h-1}/2}^{s_h/2} f dr,     m_h = nu s_h^d p_h / V_p,     V_p = V_d <r^d>   (2.14).

Cost per particle, with n_c = (3^d - 1)/2 and b(j, h) the expected number of level-j cells scanned by
a level-h particle, b = <(2r/s_j + 2)^d>_h (Eq. 2.24):

    T/N = sum_h p_h [(1/2 + n_c) m_h + sum_j m_j b(j,h) + K (1 + n_c + sum_j b(j,h))]   (2.31-2.35)

with j < h for Top-Down and j > h for Bottom-Up. The unit of time is one sphere-sphere overlap
test; K = (cell access time)/(overlap test time) ~ 0.2 (sec. 2.2.3, before Eq. 2.35; the text words the
ratio the other way round, and sec. 2.1 uses K = 0.3 with Eq. 2.7). All integrals of the power law are
done in closed form.

Cell-size distributions (ch. 2.2.5): linear (2.42), exponential (2.43-2.44), constant ratio q of
particles per cell (2.45-2.47; q = 1 recommended) and the numerical optimum over the s_h
(the text used MATLAB fmincon; here BFGS on an unconstrained parametrisation of the log-increments).

Fig. 2.15 check (alpha = -3, omega = 100, nu = 0.7, d = 3, K = 0.2, Top-Down; sec. 2.2.5): printed
linear 12.40 at L* = 43, constant-m 11.60 at L* = 12, optimal 11.58; this model gives 12.398, 11.595 and
11.574. The text also prints 11.57 for the exponential minimum, which cannot be (it would undercut the
optimum); the model gives 12.13 at L* = 4 (L* as printed), so that printed value is a misattribution. The
text's "L = 3 is 43 % worse" is 47 % here; "L = 6 is 24 % worse" agrees.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy.optimize import brentq, minimize
from scipy.special import comb

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import unit_ball_volume

METHODS = ("top-down", "bottom-up")


def n_neighbour_cells(d: int) -> int:
    """n_c = (3^d - 1)/2 neighbour cells visited per cell with the half stencil (Ogarko 2014, sec. 2.2.3,
    below Eq. 2.23).

    Parameters
    ----------
    d : int
        Dimension.

    Returns
    -------
    int
        n_c.
    """
    return (3**d - 1) // 2


def _power_integral(p: float, lo, hi):
    """int_lo^hi r^p dr (vectorised over lo, hi)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    if abs(p + 1) < 1e-12:
        return np.log(hi / lo)
    return (hi ** (p + 1) - lo ** (p + 1)) / (p + 1)


@dataclass(frozen=True)
class PowerLawSystem:
    """Radius pdf f ~ r^alpha on [1, omega] (units of r_min), volume fraction nu, dimension d.

    Attributes
    ----------
    alpha : float
        Exponent of the radius pdf.
    omega : float
        r_max / r_min, >= 1.
    nu : float
        Volume fraction, in (0, 1).
    d : int
        Dimension.
    """

    alpha: float
    omega: float
    nu: float = 0.7
    d: int = 3

    def __post_init__(self):
        if not (math.isfinite(self.alpha)):
            raise InvalidInputError(f"alpha must be finite, got {self.alpha}")
        if not (math.isfinite(self.omega) and self.omega >= 1):
            raise InvalidInputError(f"omega = r_max/r_min must be >= 1, got {self.omega}")
        if not (0 < self.nu < 1):
            raise InvalidInputError(f"volume fraction nu must lie in (0, 1), got {self.nu}")
        if self.d not in (1, 2, 3, 4, 5, 6):
            raise InvalidInputError(f"dimension d must be an integer 1..6, got {self.d}")

    def _require_polydisperse(self):
        if self.omega == 1:
            raise InvalidInputError("omega = 1 is monodisperse: only the single-level formula applies")

    def radius_moment(self, k: float, lo=1.0, hi=None):
        """int_lo^hi r^k f(r) dr with the limits clipped to the support [1, omega].

        Parameters
        ----------
        k : float
            Power of r.
        lo : float or array_like of float, default 1.0
            Lower limits (units of r_min).
        hi : float or array_like of float, optional
            Upper limits; omega if None. An upper limit below the lower one gives 0.

        Returns
        -------
        numpy.ndarray of float
            The partial moments, of the broadcast shape of ``lo`` and ``hi`` (f normalised on [1, omega]).

        Raises
        ------
        InvalidInputError
            If omega = 1 (monodisperse).
        """
        self._require_polydisperse()
        hi = self.omega if hi is None else hi
        lo_c, hi_c = np.clip(lo, 1.0, self.omega), np.clip(hi, 1.0, self.omega)
        norm = _power_integral(self.alpha, 1.0, self.omega)
        return _power_integral(k + self.alpha, lo_c, np.maximum(hi_c, lo_c)) / norm

    def cdf(self, r: float) -> float:
        """F(r) = int_1^r f dr for a scalar r (Eq. 2.47), 0 below r_min and 1 above r_max.

        Parameters
        ----------
        r : float
            Radius in units of r_min.

        Returns
        -------
        float
            F(r).

        Raises
        ------
        InvalidInputError
            If omega = 1 (monodisperse).
        """
        self._require_polydisperse()
        r = min(max(r, 1.0), self.omega)
        if abs(self.alpha + 1) < 1e-12:
            return math.log(r) / math.log(self.omega)
        return (r ** (self.alpha + 1) - 1) / (self.omega ** (self.alpha + 1) - 1)

    @property
    def particle_volume(self) -> float:
        """V_p = V_d <r^d> (Eq. 2.14)."""
        return unit_ball_volume(self.d) * float(self.radius_moment(self.d))

    def _check_cells(self, cells) -> np.ndarray:
        s = np.asarray(cells, float)
        if s.ndim != 1 or s.size < 2 or not np.isfinite(s).all():
            raise InvalidInputError("cells must be a 1-d array s_0..s_L of at least 2 finite boundaries")
        if not (np.isclose(s[0], 2.0) and np.isclose(s[-1], 2 * self.omega)):
            raise InvalidInputError(
                f"cells must start at s_0 = 2 r_min = 2 and end at s_L = 2 r_max = {2 * self.omega}; "
                f"got {s[0]} and {s[-1]}"
            )
        if np.any(np.diff(s) < 0):
            raise InvalidInputError("cell sizes must be non-decreasing (s_{h+1} >= s_h)")
        return s

    def occupancy(self, cells) -> tuple[np.ndarray, np.ndarray]:
        """(p_h, m_h) per level (Eqs. 2.17-2.19) for boundaries s_0..s_L.

        Parameters
        ----------
        cells : array_like of float, shape (L + 1,)
            Non-decreasing cell sizes s_0 = 2 .. s_L = 2 omega (units of r_min).

        Returns
        -------
        p : numpy.ndarray of float, shape (L,)
            Fraction of the particles on each level.
        m : numpy.ndarray of float, shape (L,)
            Mean number of the level's particles per level cell.

        Raises
        ------
        InvalidInputError
            If the boundaries are not as above, or omega = 1.
        """
        s = self._check_cells(cells)
        p = self.radius_moment(0, s[:-1] / 2, s[1:] / 2)
        return p, self.nu * s[1:] ** self.d * p / self.particle_volume

    def cost(self, cells, K: float = 0.2, method: str = "top-down") -> float:
        """Expected work per particle T/N, Eq. 2.35 with (2.31-2.34), for boundaries s_0..s_L.

        Parameters
        ----------
        cells : array_like of float, shape (L + 1,)
            Non-decreasing cell sizes s_0 = 2 .. s_L = 2 omega (units of r_min).
        K : float, default 0.2
            Cell access time over overlap-test time, >= 0.
        method : {"top-down", "bottom-up"}, default "top-down"
            Search direction across levels.

        Returns
        -------
        float
            T/N in units of one overlap test.

        Raises
        ------
        InvalidInputError
            If ``method`` is unknown, K is negative, the boundaries are not as above, or omega = 1.
        """
        if method not in METHODS:
            raise InvalidInputError(f"method must be one of {METHODS}, got {method!r}")
        if not (K >= 0):
            raise InvalidInputError(f"K must be >= 0, got {K}")
        s = self._check_cells(cells)
        p, m = self.occupancy(s)
        nc, d = n_neighbour_cells(self.d), self.d
        # Q[j, h] = p_h b(j, h) = int_h (2 r/s_j + 2)^d f dr, expanded binomially (Eq. 2.24)
        ks = np.arange(d + 1)
        moments = np.array([self.radius_moment(k, s[:-1] / 2, s[1:] / 2) for k in ks])  # (d+1, L)
        coef = comb(d, ks) * 2.0 ** (d - ks) * (2.0 / s[1:, None]) ** ks  # (L_j, d+1)
        Q = coef @ moments
        L = len(p)
        j, h = np.indices((L, L))
        cross = (j < h) if method == "top-down" else (j > h)
        same = np.sum(p * ((0.5 + nc) * m + K * (1 + nc)))
        return float(same + np.sum(np.where(cross, (m[:, None] + K) * Q, 0.0)))

    def linked_cell_m(self) -> float:
        """m_1 of the single-level grid (s_1 = 2 r_max), Eq. 2.40:
        m_1 = (2 omega)^d nu/V_d (1+d+alpha)/(1+alpha) (omega^(1+alpha) - 1)/(omega^(1+d+alpha) - 1),
        evaluated as (2 omega)^d nu/V_d int f/int r^d f so alpha = -1, -1-d and omega = 1 (m_1 = 2^d nu/V_d)
        are covered. (Eq. 2.41's "lim alpha -> inf" means omega -> inf.)"""
        ratio = 1.0
        if self.omega > 1:
            ratio = float(
                _power_integral(self.alpha, 1.0, self.omega) / _power_integral(self.alpha + self.d, 1.0, self.omega)
            )
        return (2 * self.omega) ** self.d * self.nu / unit_ball_volume(self.d) * ratio

    def linked_cell_cost(self, K: float = 0.2) -> float:
        """T/N of the single-level linked-cell method, (1/2 + n_c) m_1 + K (1 + n_c) (Eqs. 2.35, 2.39-2.40).

        Parameters
        ----------
        K : float, default 0.2
            Cell access time over overlap-test time.

        Returns
        -------
        float
            T/N in units of one overlap test (omega = 1 allowed).
        """
        nc = n_neighbour_cells(self.d)
        return (0.5 + nc) * self.linked_cell_m() + K * (1 + nc)


def _check_levels(L):
    if int(L) != L or L < 1:
        raise InvalidInputError(f"number of levels L must be a positive integer, got {L!r}")
    return int(L)


def linear_cells(L: int, omega: float) -> np.ndarray:
    """s_h = 2 r_min (1 + h (omega - 1)/L), h = 0..L (Eq. 2.42).

    Parameters
    ----------
    L : int
        Number of levels, >= 1.
    omega : float
        r_max / r_min.

    Returns
    -------
    numpy.ndarray of float, shape (L + 1,)
        s_0..s_L in units of r_min.
    """
    L = _check_levels(L)
    return 2.0 * (1 + np.arange(L + 1) * (omega - 1) / L)


def exponential_cells(L: int, omega: float) -> np.ndarray:
    """s_h = 2 r_min omega^(h/L), h = 0..L (Eqs. 2.43-2.44).

    Parameters
    ----------
    L : int
        Number of levels, >= 1.
    omega : float
        r_max / r_min.

    Returns
    -------
    numpy.ndarray of float, shape (L + 1,)
        s_0..s_L in units of r_min.
    """
    L = _check_levels(L)
    return 2.0 * omega ** (np.arange(L + 1) / L)


def constant_m_cells(system: PowerLawSystem, L: int, q: float = 1.0) -> np.ndarray:
    """Cell sizes with m_{h+1} = q m_h (Eqs. 2.45-2.47), s_0 = 2 r_min, s_L = 2 r_max.

    Solved by shooting: for a trial m_1 each s_h follows from s_h^d [F(s_h/2) - F(s_{h-1}/2)] = c q^(h-1)
    (monotone in s_h), and m_1 is adjusted until s_L = 2 omega.

    Parameters
    ----------
    system : PowerLawSystem
        The radius distribution (polydisperse).
    L : int
        Number of levels, >= 1.
    q : float, optional
        Ratio of the particles per cell of successive levels, > 0.

    Returns
    -------
    numpy.ndarray of float, shape (L + 1,)
        s_0..s_L in units of r_min.
    """
    L = _check_levels(L)
    if not (q > 0):
        raise InvalidInputError(f"q must be positive, got {q}")
    system._require_polydisperse()
    return np.array(_constant_m_cells(system, L, float(q)))


@functools.lru_cache(maxsize=1024)
def _constant_m_cells(system: PowerLawSystem, L: int, q: float) -> tuple[float, ...]:
    """:func:`constant_m_cells` (a pure function of its arguments, kept for the callers that ask
    again)."""
    top, d = 2.0 * system.omega, system.d

    def advance(s_prev, target):
        f_prev = system.cdf(s_prev / 2)
        if f_prev >= 1.0 - 1e-15:
            return math.inf

        def g(s):
            return s**d * (system.cdf(s / 2) - f_prev) - target

        hi = 2 * max(top, s_prev)
        while g(hi) < 0:
            hi *= 2
        return brentq(g, s_prev, hi, xtol=1e-14, rtol=1e-14)

    def shoot(log_c):
        s = [2.0]
        for h in range(L):
            s.append(advance(s[-1], math.exp(log_c) * q**h))
            if not math.isfinite(s[-1]):
                break
        return s

    def miss(log_c):
        last = shoot(log_c)[-1]
        return math.log(last / top) if math.isfinite(last) else 50.0

    # bracket: all targets tiny (s_L -> s_0) .. first level alone already beyond 2 r_max
    log_lo = math.log(1e-12) - (L - 1) * max(0.0, math.log(q))
    log_c = brentq(miss, log_lo, d * math.log(top) + 1.0, xtol=1e-13)
    s = shoot(log_c)
    s[-1] = top
    return tuple(float(x) for x in s)


def _cells_from_free(z, omega):
    """Boundaries from L-1 free reals: log-increments u = ln(omega) softmax([z, 0]) (all >= 0)."""
    z = np.append(z, 0.0)
    u = np.exp(z - z.max())
    u = math.log(omega) * u / u.sum()
    return 2.0 * np.exp(np.concatenate([[0.0], np.cumsum(u)]))


def optimal_cells(system: PowerLawSystem, L: int, K: float = 0.2, method: str = "top-down") -> np.ndarray:
    """Cell sizes minimising T/N for fixed L (ch. 2.2.5 "optimal"), starting from the constant-m solution.

    The constraint s_{h+1} >= s_h with fixed ends is built in by writing the L log-increments as
    ln(omega) times a softmax of L-1 free parameters; BFGS with numerical gradients.

    Parameters
    ----------
    system : PowerLawSystem
        The radius distribution.
    L : int
        Number of levels, >= 1.
    K : float, optional
        Cost ratio of a cell visit to a distance test.
    method : str, optional
        Search method of the cost model, "top-down" or "bottom-up".

    Returns
    -------
    numpy.ndarray of float, shape (L + 1,)
        s_0..s_L in units of r_min.
    """
    L = _check_levels(L)
    if L == 1:
        return np.array([2.0, 2.0 * system.omega])
    return _cells_from_free(np.array(_optimal_free(system, L, float(K), method)), system.omega)


@functools.lru_cache(maxsize=256)
def _optimal_free(system: PowerLawSystem, L: int, K: float, method: str) -> tuple[float, ...]:
    """The free parameters of :func:`optimal_cells` (a pure function of its arguments, kept for
    the callers that ask again, e.g. every ``hardpack validate`` of one process)."""
    start = np.log(np.diff(np.log(constant_m_cells(system, L))))
    z0 = start[:-1] - start[-1]
    res = minimize(lambda z: system.cost(_cells_from_free(z, system.omega), K, method), z0, method="BFGS")
    return tuple(float(x) for x in res.x)


CELL_RULES = ("linear", "exponential", "constant-m", "optimal")


def cells_for(system: PowerLawSystem, rule: str, L: int, K: float = 0.2, method: str = "top-down"):
    """Boundaries s_0..s_L of the named cell-size rule (one of CELL_RULES; constant-m uses q = 1).

    Parameters
    ----------
    system : PowerLawSystem
        The radius distribution.
    rule : str
        One of CELL_RULES.
    L : int
        Number of levels, >= 1.
    K : float, optional
        Cost ratio (rule "optimal").
    method : str, optional
        Search method (rule "optimal").

    Returns
    -------
    numpy.ndarray of float, shape (L + 1,)
        s_0..s_L in units of r_min.

    Raises
    ------
    InvalidInputError
        For an unknown rule.
    """
    if rule == "linear":
        return linear_cells(L, system.omega)
    if rule == "exponential":
        return exponential_cells(L, system.omega)
    if rule == "constant-m":
        return constant_m_cells(system, L)
    if rule == "optimal":
        return optimal_cells(system, L, K, method)
    raise InvalidInputError(f"unknown cell-size rule {rule!r}; choose one of {CELL_RULES}")


def cost_vs_levels(system: PowerLawSystem, rule: str, levels, K: float = 0.2, method: str = "top-down") -> np.ndarray:
    """T/N for each L in ``levels`` with the named cell-size rule (the curves of Figs. 2.12 and 2.15).

    Parameters
    ----------
    system : PowerLawSystem
        The radius distribution.
    rule : str
        One of CELL_RULES.
    levels : iterable of int
        Numbers of levels.
    K : float, optional
        Cost ratio of a cell visit to a distance test.
    method : str, optional
        "top-down" or "bottom-up".

    Returns
    -------
    numpy.ndarray of float
        T/N for each L.
    """
    return np.array([system.cost(cells_for(system, rule, L, K, method), K, method) for L in levels])


def best_levels(system: PowerLawSystem, rule: str, L_max: int = 60, K: float = 0.2, method: str = "top-down"):
    """(L*, T*/N, cells) minimising T/N over 1 <= L <= L_max for the named rule (Figs. 2.10-2.15).

    Parameters
    ----------
    system : PowerLawSystem
        The radius distribution.
    rule : str
        One of CELL_RULES.
    L_max : int, optional
        Most levels tried.
    K : float, optional
        Cost ratio of a cell visit to a distance test.
    method : str, optional
        "top-down" or "bottom-up".

    Returns
    -------
    levels : int
        L*.
    cost : float
        T*/N.
    cells : numpy.ndarray of float, shape (L* + 1,)
        Its cell boundaries.
    """
    levels = np.arange(1, _check_levels(L_max) + 1)
    costs = cost_vs_levels(system, rule, levels, K, method)
    best = int(np.argmin(costs))
    return int(levels[best]), float(costs[best]), cells_for(system, rule, int(levels[best]), K, method)


def cost_dataset(system: PowerLawSystem, rules, levels, K: float, method: str) -> xr.Dataset:
    """The analytic cost T/N (Ogarko 2014, Eq. 2.35) of every cell-size rule at every number of
    levels, with the single-level (linked-cell) cost for reference.

    Parameters
    ----------
    system : PowerLawSystem
        Power-law radii, volume fraction and dimension.
    rules : sequence of str
        Cell-size rules of :data:`CELL_RULES`.
    levels : sequence of int
        Numbers of levels.
    K : float
        Ratio of the time of a cell access to that of an overlap test.
    method : str
        Search method of :data:`METHODS`.

    Returns
    -------
    xarray.Dataset
        ``cost(rule, levels)``, ``hardpack_kind = "hgrid_cost"``; the system, K, method and
        ``linked_cell_cost`` as attributes.
    """
    levels = np.asarray(levels, dtype=int)
    cost = np.array([cost_vs_levels(system, rule, levels, K, method) for rule in rules])
    ds = xr.Dataset({"cost": (("rule", "levels"), cost)}, coords={"rule": list(rules), "levels": levels})
    ds["cost"].attrs["long_name"] = "contact-detection work per particle T/N (Eq. 2.35)"
    ds.attrs.update(
        hardpack_kind="hgrid_cost",
        alpha=system.alpha,
        omega=system.omega,
        nu=system.nu,
        d=system.d,
        K=K,
        method=method,
        linked_cell_cost=system.linked_cell_cost(K),
    )
    return ds
