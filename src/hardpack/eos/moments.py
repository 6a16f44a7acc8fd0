"""Moments of radius distributions and moment-matched (equivalent) mixtures (Ogarko 2014, ch. 3).

Notation follows Ogarko 2014 (sec. 3.1.2, the appendix of sec. 3.1, sec. 3.2 and Eq. 3.38):

- raw moments <a^k> of the number pdf f(a) of radii;
- scaled moments M_k = <a^k> / <a>^k and central scaled moments M^c_k = <(a - <a>)^k> / <a>^k;
- O1 = <a><a^2>/<a^3> and O2 = <a^2>^3/<a^3>^2 (Eq. 3.6), the only PSD input of every fluid EOS;
- polydispersity delta = std(a)/<a> = (O2/O1^2 - 1)^(1/2), skewness, kurtosis beta2 = M^c_4/(M^c_2)^2;
- mean diameters D_pq = 2 (<a^p>/<a^q>)^(1/(p-q)) (sec. 3.1.2).

A *source* is either a :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array
of radii (sample moments, e.g. ``Packing.radii`` or ``distribution.sample(n)``).

Equivalent mixtures. The bidisperse system that matches <a^0>..<a^3> (Eqs. 3.20-3.21, ch. 3.1) and
the "maximally equivalent" tridisperse system that matches <a^0>..<a^5> (ch. 3.2, Tables 3.2-3.4)
are exactly the 2- and 3-node Gauss quadratures of f(a) (derived here: an s-node Gauss quadrature
matches <a^0>..<a^(2s-1)>, as many moments as an s-disperse mixture has free parameters). They are computed here
by the Chebyshev algorithm (Gautschi, "On generating orthogonal polynomials", SIAM J. Sci. Stat.
Comput. 3, 289 (1982)) applied to the central scaled moments, followed by Golub-Welsch (eigen-
decomposition of the symmetric tridiagonal Jacobi matrix). Working in the scaled, centred variable
a/<a> - 1 keeps the 3x3 problem well conditioned up to the log-normal with sigma = 1 (M_5 = e^10) and
beyond (checked against a 50-digit solve for sigma = 0.05-1.5 while writing the tests); every result is
checked by back-substitution of the moments. The precision is limited by that of the central moments
(see :func:`central_scaled_moments`): ~1e-10 in general, ~1e-5 for a log-normal as narrow as sigma = 0.01.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad
from scipy.linalg import eigh_tridiagonal
from scipy.special import comb

from hardpack.distributions import Discrete, Distribution, monodisperse
from hardpack.errors import InvalidInputError

#: relative tolerance of the back-substituted moments of an equivalent mixture
MOMENT_RTOL = 1e-9
#: a variance beta_1 (in units of <a>^2) below this, or a Jacobi coefficient beta_k below this fraction of
#: beta_1, means fewer than k + 1 distinct radii
_DEGENERATE = 1e-10


def _as_source(source):
    if isinstance(source, Distribution):
        return source
    a = np.asarray(source, dtype=float)
    if a.ndim != 1 or a.size == 0:
        raise InvalidInputError(
            f"radii must be a non-empty 1-d array or a hardpack.distributions.Distribution, got shape {a.shape}"
        )
    if not (np.isfinite(a).all() and (a > 0).all()):
        raise InvalidInputError("radii must be positive and finite; remove zero, negative or NaN radii")
    return a


def _check_order(kmax):
    if int(kmax) != kmax or kmax < 0:
        raise InvalidInputError(f"kmax must be a non-negative integer, got {kmax!r}")
    return int(kmax)


def raw_moment(source, k: float) -> float:
    """<a^k> (any real k): analytic for a Distribution, the sample mean of a^k for an array.

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).
    k : float
        The order.

    Returns
    -------
    float
        <a^k>.

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii.
    """
    src = _as_source(source)
    if isinstance(src, Distribution):
        return float(src.moment(k))
    return float(np.mean(src**k))


def raw_moments(source, kmax: int = 5) -> np.ndarray:
    """<a^k> for k = 0..kmax.

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).
    kmax : int, default 5
        Highest order, >= 0.

    Returns
    -------
    numpy.ndarray
        (kmax + 1,) <a^0>..<a^kmax>.

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii, or
        kmax is not a non-negative integer.
    """
    return np.array([raw_moment(source, k) for k in range(_check_order(kmax) + 1)])


def scaled_moments(source, kmax: int = 5) -> np.ndarray:
    """M_k = <a^k>/<a>^k for k = 0..kmax (Ogarko 2014, sec. 3.2).

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).
    kmax : int, default 5
        Highest order, >= 0.

    Returns
    -------
    numpy.ndarray
        (kmax + 1,) M_0..M_kmax.

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii, or
        kmax is not a non-negative integer.
    """
    mu = raw_moments(source, kmax)
    return mu / raw_moment(source, 1) ** np.arange(kmax + 1)


def central_scaled_moments(source, kmax: int = 5) -> np.ndarray:
    """M^c_k = <(a - <a>)^k>/<a>^k for k = 0..kmax (Eq. 3.38).

    Samples and discrete mixtures are centred directly, continuous distributions with bounded
    support are integrated numerically (adaptive quadrature of the pdf, ~1e-12 in units of
    delta^k), so no precision is lost for narrow distributions. Unbounded ones (log-normal) use the
    binomial expansion of the analytic scaled moments, which loses about log10(1/delta^k) digits:
    ~1e-10 relative for delta >= 0.05 and k <= 5.

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).
    kmax : int, default 5
        Highest order, >= 0.

    Returns
    -------
    numpy.ndarray
        (kmax + 1,) M^c_0..M^c_kmax (M^c_0 = 1, M^c_1 = 0 up to round-off).

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii, or
        kmax is not a non-negative integer.
    """
    kmax = _check_order(kmax)
    src = _as_source(source)
    orders = np.arange(kmax + 1)
    if isinstance(src, Discrete):
        r, w = np.asarray(src.radii), np.asarray(src.fractions)
        x = r / np.sum(w * r) - 1.0
        return np.array([np.sum(w * x**k) for k in orders])
    if not isinstance(src, Distribution):
        x = src / src.mean() - 1.0
        return np.array([np.mean(x**k) for k in orders])
    lo, hi = src.support
    mean = src.moment(1)
    if math.isfinite(hi):

        def integrand(a, k):
            return src.pdf(a) * (a / mean - 1.0) ** k

        out = [1.0, 0.0, quad(integrand, lo, hi, args=(2,), epsabs=0.0, epsrel=1e-12, limit=200)[0]]
        for k in range(3, kmax + 1):  # odd moments may vanish: absolute tolerance on the delta^k scale
            tol = 1e-12 * out[2] ** (k / 2)
            out.append(quad(integrand, lo, hi, args=(k,), epsabs=tol, epsrel=1e-12, limit=200)[0])
        return np.array(out[: kmax + 1])
    m = scaled_moments(src, kmax)
    return np.array([sum(comb(k, j, exact=True) * m[j] * (-1.0) ** (k - j) for j in range(k + 1)) for k in orders])


def dimensionless_moments(source) -> tuple[float, float]:
    """(O1, O2) = (<a><a^2>/<a^3>, <a^2>^3/<a^3>^2) (Eq. 3.6); 0 < O1 <= 1, O1^2 <= O2 <= O1.

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).

    Returns
    -------
    tuple of float
        (O1, O2).

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii.
    """
    m1, m2, m3 = (raw_moment(source, k) for k in (1, 2, 3))
    return m1 * m2 / m3, m2**3 / m3**2


def polydispersity(source) -> float:
    """delta = std(a)/<a> (Ogarko 2014, appendix of sec. 3.1).

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).

    Returns
    -------
    float
        delta >= 0 (0 for a monodisperse source).

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii.
    """
    return math.sqrt(max(central_scaled_moments(source, 2)[2], 0.0))


def skewness(source) -> float:
    """M^c_3/(M^c_2)^(3/2); NaN for a monodisperse source (undefined).

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).

    Returns
    -------
    float
        The skewness, NaN for a monodisperse source.

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii.
    """
    c = central_scaled_moments(source, 3)
    return c[3] / c[2] ** 1.5 if c[2] > 0 else math.nan


def kurtosis(source) -> float:
    """beta2 = M^c_4/(M^c_2)^2 >= 1 (sec. 3.2, Eq. 3.41); 1.8 for uniform size; NaN if monodisperse.

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).

    Returns
    -------
    float
        beta2, NaN for a monodisperse source.

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii.
    """
    c = central_scaled_moments(source, 4)
    return c[4] / c[2] ** 2 if c[2] > 0 else math.nan


def mean_diameter(source, p: float, q: float) -> float:
    """D_pq = 2 (<a^p>/<a^q>)^(1/(p-q)) (Ogarko 2014, sec. 3.1.2); e.g. D_10 = 2<a>, D_32 = Sauter diameter.

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).
    p, q : float
        The orders, p != q.

    Returns
    -------
    float
        D_pq.

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii, or p
        == q.
    """
    if p == q:
        raise InvalidInputError(f"D_pq needs p != q, got p = q = {p}")
    return 2.0 * (raw_moment(source, p) / raw_moment(source, q)) ** (1.0 / (p - q))


# --- Gauss quadrature of the radius distribution ------------------------------------------------


def _chebyshev(mom: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Recurrence coefficients alpha_0..n-1, beta_0..n-1 from ordinary moments mom[0..2n-1]
    (Gautschi 1982, Chebyshev algorithm). Refuses measures with fewer than n support points."""
    alpha, beta = np.zeros(n), np.zeros(n)
    sig_prev = np.zeros(2 * n)
    sig = mom[: 2 * n].astype(float).copy()
    alpha[0], beta[0] = mom[1] / mom[0], mom[0]
    for k in range(1, n):
        new = np.zeros(2 * n)
        for ell in range(k, 2 * n - k):
            new[ell] = sig[ell + 1] - alpha[k - 1] * sig[ell] - beta[k - 1] * sig_prev[ell]
        beta[k] = new[k] / sig[k - 1]
        if not beta[k] > _DEGENERATE * (beta[1] if k > 1 else 1.0):
            raise InvalidInputError(
                f"the size distribution has fewer than {n} distinct radii, so it has no {n}-species "
                "equivalent; use the distribution itself"
            )
        alpha[k] = new[k + 1] / new[k] - sig[k] / sig[k - 1]
        sig_prev, sig = sig, new
    return alpha, beta


def gauss_quadrature(source, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-node Gauss quadrature of the radius pdf: radii a_i (descending) and number fractions n_i.

    sum_i n_i a_i^k = <a^k> for k = 0..2n-1. Raises InvalidInputError if the source has fewer
    than n distinct radii (the quadrature would have coincident nodes) or if the back-substituted
    central moments miss the input by more than MOMENT_RTOL on the scale max(|M^c_k|, delta^k).

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).
    n : int
        Number of nodes, >= 1.

    Returns
    -------
    radii : numpy.ndarray
        (n,) nodes a_i, descending.
    fractions : numpy.ndarray
        (n,) number fractions n_i, summing to 1.

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii, n is
        not a positive integer, or as above.
    """
    if int(n) != n or n < 1:
        raise InvalidInputError(f"number of nodes must be a positive integer, got {n!r}")
    n = int(n)
    src = _as_source(source)
    central = central_scaled_moments(src, 2 * n - 1)
    alpha, beta = _chebyshev(central, n)
    x, vec = eigh_tridiagonal(alpha, np.sqrt(beta[1:]))
    weights = vec[0] ** 2
    mean = raw_moment(src, 1)
    radii = mean * (1.0 + x)
    # back-substitution of the central moments, each on its natural scale max(|M^c_k|, delta^k)
    orders = np.arange(2 * n)
    got = np.array([np.sum(weights * x**k) for k in orders])
    scale = np.maximum(np.abs(central), central[2] ** (orders / 2)) if n > 1 else np.ones(2)
    err = np.max(np.abs(got - central) / scale)
    if not err <= MOMENT_RTOL or radii[-1] <= 0:
        raise InvalidInputError(
            f"the {n}-node quadrature reproduces the moments only to {err:.1e} (radii {radii}); "
            "the distribution is too narrow or too wide for double precision"
        )
    return radii[::-1], weights[::-1] / weights.sum()


@dataclass(frozen=True)
class BidisperseEquivalent:
    """Equivalent bidisperse system (Eqs. 3.20-3.21): same <a^0>..<a^3>, hence same O1, O2, <a>.

    Attributes
    ----------
    mixture : Discrete
        The two species, with the source's <a>.
    n1 : float
        Number fraction of the large species.
    R : float
        Size ratio a1 / a2 >= 1.
    """

    mixture: Discrete
    n1: float
    R: float


@dataclass(frozen=True)
class TridisperseEquivalent:
    """Maximally equivalent tridisperse system (ch. 3.2): same <a^0>..<a^5>.

    Ogarko's parametrisation (Ogarko 2014, Table 3.2) with a1 >= a2 >= a3: number fractions n1, n2
    (n3 = 1 - n1 - n2) and delta_i = n_i a_i/<a> (so a_i = <a> delta_i / n_i).

    Attributes
    ----------
    mixture : Discrete
        The three species (number fractions n1, n2, n3).
    n1, n2 : float
        Number fractions of the largest and the middle species.
    delta1, delta2 : float
        delta_i = n_i a_i / <a> of the largest and the middle species.
    """

    mixture: Discrete
    n1: float
    n2: float
    delta1: float
    delta2: float

    @property
    def radii(self) -> np.ndarray:
        """a1 >= a2 >= a3 in units of <a>."""
        n3 = 1.0 - self.n1 - self.n2
        return np.array([self.delta1 / self.n1, self.delta2 / self.n2, (1 - self.delta1 - self.delta2) / n3])


def equivalent_bidisperse(source) -> BidisperseEquivalent:
    """Bidisperse equivalent = 2-node Gauss quadrature (derived here, see the module docstring).

    For a monodisperse source it returns R = 1, n1 = 1/2 (Table 3.1, row omega = 1), the narrow
    limit of every smooth distribution (its skewness vanishes).

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).

    Returns
    -------
    BidisperseEquivalent
        The mixture and its (n1, R).

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii, or
        the quadrature fails (:func:`gauss_quadrature`).
    """
    src = _as_source(source)
    if central_scaled_moments(src, 2)[2] <= _DEGENERATE:
        return BidisperseEquivalent(monodisperse(raw_moment(src, 1)), 0.5, 1.0)
    radii, frac = gauss_quadrature(src, 2)
    return BidisperseEquivalent(Discrete(tuple(radii), tuple(frac)), float(frac[0]), float(radii[0] / radii[1]))


def equivalent_tridisperse(source) -> TridisperseEquivalent:
    """Maximally equivalent tridisperse system = 3-node Gauss quadrature (derived here, see the module docstring).

    Reproduces Tables 3.3 (UV) and 3.4 (log-normal) and the 5:8:5 US solution (Eqs. 3.39-3.40).

    Parameters
    ----------
    source : Distribution or array_like
        A :class:`hardpack.distributions.Distribution` (analytic moments) or a 1-d array of radii
        (sample moments).

    Returns
    -------
    TridisperseEquivalent
        The mixture and its (n1, n2, delta1, delta2).

    Raises
    ------
    InvalidInputError
        If source is neither a Distribution nor a non-empty 1-d array of positive finite radii, the
        source has fewer than 3 distinct radii, or the quadrature misses the moments
        (:func:`gauss_quadrature`).
    """
    src = _as_source(source)
    radii, frac = gauss_quadrature(src, 3)
    delta = frac * radii / raw_moment(src, 1)
    return TridisperseEquivalent(
        Discrete(tuple(radii), tuple(frac)), float(frac[0]), float(frac[1]), float(delta[0]), float(delta[1])
    )


def bidisperse_from_O(O1: float, O2: float) -> tuple[float, float]:
    """Closed form (n1, R) of the bidisperse equivalent from (O1, O2), Ogarko 2014, Eqs. 3.20-3.21.

    lambda = sqrt(O2) sqrt(4 O1^3 + O2 - 3 O1 (2 + O1) O2 + 4 O2^2),
    n1 = 1/2 + (3 O1 O2 - O2 - 2 O1^3)/(2 lambda),
    R = [2 O1^3 + 2 O2^2 + O2 - 4 O1 O2 - O1^2 O2 + (1 - O1) lambda] / [2 (O2 - O1)(O1^2 - O2)].
    Monodisperse (O1 = O2 = 1) returns (1/2, 1) as in Table 3.1.

    Parameters
    ----------
    O1, O2 : float
        The dimensionless moments (Eq. 3.6).

    Returns
    -------
    tuple of float
        (n1, R): number fraction of the large species and size ratio a1 / a2.

    Raises
    ------
    InvalidInputError
        If (O1, O2) is not realisable: 0 < O1 <= 1 and O1^2 <= O2 <= O1 are needed.
    """
    if not (0 < O1 <= 1 + 1e-12 and O1**2 * (1 - 1e-12) <= O2 <= O1 * (1 + 1e-12)):
        raise InvalidInputError(
            f"(O1, O2) = ({O1}, {O2}) is not realisable: need 0 < O1 <= 1 and O1^2 <= O2 <= O1 "
            "(Ogarko 2014, sec. 3.1.2)"
        )
    if abs(O1 - 1) < 1e-12 and abs(O2 - 1) < 1e-12:  # monodisperse up to round-off
        return 0.5, 1.0
    lam = math.sqrt(O2) * math.sqrt(4 * O1**3 + O2 - 3 * O1 * (2 + O1) * O2 + 4 * O2**2)
    n1 = 0.5 + (3 * O1 * O2 - O2 - 2 * O1**3) / (2 * lam)
    num = 2 * O1**3 + 2 * O2**2 + O2 - 4 * O1 * O2 - O1**2 * O2 + (1 - O1) * lam
    return n1, num / (2 * (O2 - O1) * (O1**2 - O2))


def _tridisperse(n1, n2, delta1, delta2, mean_radius) -> TridisperseEquivalent:
    n3 = 1.0 - n1 - n2
    radii = mean_radius * np.array([delta1 / n1, delta2 / n2, (1.0 - delta1 - delta2) / n3])
    mixture = Discrete(tuple(radii), (n1, n2, n3))
    return TridisperseEquivalent(mixture, n1, n2, delta1, delta2)


def _omega0(omega: float) -> float:
    if not (math.isfinite(omega) and omega > 1):
        raise InvalidInputError(f"omega must be > 1 (a_max/a_min of the US distribution), got {omega}")
    return (omega - 1) / (omega + 1)


def tridisperse_uniform_size(omega: float, mean_radius: float = 1.0) -> TridisperseEquivalent:
    """Analytic maximal equivalent of the US distribution, Ogarko 2014, Eqs. 3.39-3.40:

    n1 = 5/18, n2 = 8/18, delta1 = (5 + sqrt(15) omega0)/18, delta2 = 8/18 with
    omega0 = (omega - 1)/(omega + 1), i.e. radii <a>(1 + sqrt(3/5) omega0), <a>, <a>(1 - sqrt(3/5) omega0)
    in the ratio 5:8:5 (3-point Gauss-Legendre).

    Parameters
    ----------
    omega : float
        Width a_max / a_min of the US distribution, finite and > 1.
    mean_radius : float, default 1.0
        <a> of the mixture.

    Returns
    -------
    TridisperseEquivalent
        The 5:8:5 mixture.

    Raises
    ------
    InvalidInputError
        If omega is not a finite number > 1.
    """
    w0 = _omega0(omega)
    return _tridisperse(5 / 18, 8 / 18, (5 + math.sqrt(15) * w0) / 18, 8 / 18, mean_radius)


def kurtosis_family(omega: float, beta2: float, mean_radius: float = 1.0) -> TridisperseEquivalent:
    """Symmetric tridisperse system with the central moments M^c_2, M^c_3, M^c_5 of US(omega) and
    kurtosis beta2 = M^c_4/(M^c_2)^2.

    Generalises Eqs. 3.41-3.42 (printed for omega = 3, Ogarko 2014, sec. 3.3.2) to any omega:
    n1 = n3 = 1/(2 beta2), n2 = (beta2 - 1)/beta2, delta1 = (1 + omega0 sqrt(beta2/3))/(2 beta2),
    delta2 = n2, i.e. radii <a>(1 +- omega0 sqrt(beta2/3)) and <a>. For omega = 3 (omega0 = 1/2)
    delta1 = (6 + sqrt(3 beta2))/(12 beta2) as printed. beta2 = 1.8 is the maximally equivalent
    system (Eqs. 3.39-3.40). Allowed: 1 < beta2 < 3/omega0^2 (beta2 = 1 is bidisperse; at the upper
    end the smallest radius reaches 0, beta2 = 12 for omega = 3, sec. 3.2).

    Parameters
    ----------
    omega : float
        Width a_max / a_min of the US distribution, finite and > 1.
    beta2 : float
        Kurtosis, 1 < beta2 < 3 / omega0^2.
    mean_radius : float, default 1.0
        <a> of the mixture.

    Returns
    -------
    TridisperseEquivalent
        The symmetric mixture.

    Raises
    ------
    InvalidInputError
        If omega is not a finite number > 1 or beta2 is outside (1, 3 / omega0^2).
    """
    w0 = _omega0(omega)
    if not (1 < beta2 < 3 / w0**2):
        raise InvalidInputError(
            f"kurtosis beta2 = {beta2} outside (1, 3/omega0^2) = (1, {3 / w0**2:.4g}) for omega = {omega}"
        )
    n1, n2 = 1 / (2 * beta2), (beta2 - 1) / beta2
    return _tridisperse(n1, n2, (1 + w0 * math.sqrt(beta2 / 3)) / (2 * beta2), n2, mean_radius)
