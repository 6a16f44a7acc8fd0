"""Particle-size distributions, parameterised as in Ogarko's dissertation (Ogarko 2014, ch. 2-3).

Every distribution is a number pdf f(a) of sphere radii a. Widths follow Ogarko: omega is always
the ratio of radii a_max / a_min (Ogarko 2014, secs. 2.1.2 and 3.1.3). Scale: every continuous
distribution is normalised to mean radius <a> = ``mean_radius`` (default 1), which is the unit of
length of ch. 3 (Table 3.2); packings are rescaled to the target density afterwards, so only the
shape of the distribution matters.

- :class:`Monodisperse`
- :class:`Discrete` (bidisperse, tridisperse equivalents, any finite mixture) and
  :func:`bidisperse` (size ratio R = a_large / a_small, number fraction x of the large species)
- :class:`PowerLaw` f(a) ~ a^alpha on [a_min, omega a_min] (ch. 2.2, Eq. 2.37); alpha = 0 is
  uniform in size (US), alpha = -3 the "uniform volume" (UV) distribution f ~ a^-3 of ch. 3
  (Eq. 3.43; strictly uniform in a^-2, as Ogarko 2014, Eq. 3.45, notes)
- :func:`uniform_size` (US) and :func:`uniform_volume` (UV)
- :class:`LogNormal` f(a) = exp(-(ln(a/a0))^2 / (2 sigma^2)) / (sigma sqrt(2 pi) a) (Eq. 3.46),
  with <a^k> = a0^k exp(k^2 sigma^2 / 2) (Eq. 3.47)

Each has analytic raw moments <a^k> (any real k >= 0 for the continuous ones), a quantile
function, and ``sample(n, rng)`` with systematic (stratified-quantile) sampling: radius i is
F^-1((i + u) / n) with one uniform offset u (u = 1/2 when no generator is given). This is the
"systematic sampling" of Ogarko 2014, secs. 2.1.3 and 3.1.3, which guarantees that the rare largest sizes
are present even in small systems.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError


def _systematic_u(n: int, rng) -> np.ndarray:
    if int(n) != n or n < 1:
        raise InvalidInputError(f"number of particles must be a positive integer, got {n!r}")
    offset = 0.5 if rng is None else float(rng.random())
    return (np.arange(int(n)) + offset) / n


class Distribution:
    """Common interface: ``moment(k)``, ``ppf(q)``, ``pdf(a)``, ``support``, ``sample``."""

    name = "distribution"

    def moment(self, k: float) -> float:
        """Raw moment <a^k> of the radius distribution.

        Parameters
        ----------
        k : float
            Order of the moment (k >= 0; the continuous distributions take any real k).

        Returns
        -------
        float
            <a^k> = int a^k f(a) da (sum_s n_s a_s^k for a discrete mixture).
        """
        raise NotImplementedError

    def ppf(self, q):
        """Quantile function F^-1(q): the radius below which a fraction q of the particles lies.

        Parameters
        ----------
        q : float or array_like of float
            Cumulative number fractions, in [0, 1].

        Returns
        -------
        float or numpy.ndarray of float
            Radii, of the shape of ``q``.
        """
        raise NotImplementedError

    def pdf(self, a):
        """Number density f(a) of the radii.

        Parameters
        ----------
        a : float or array_like of float
            Radii.

        Returns
        -------
        float or numpy.ndarray of float
            f(a), of the shape of ``a``; 0 outside the support.

        Raises
        ------
        InvalidInputError
            For a discrete mixture, which has no density.
        """
        raise NotImplementedError

    @property
    def support(self) -> tuple[float, float]:
        raise NotImplementedError

    def sample(self, n: int, rng: np.random.Generator | None = None) -> np.ndarray:
        """n radii by systematic sampling, sorted ascending (shuffle positions, not radii).

        Radius i is F^-1((i + u) / n) with one offset u (module docstring).

        Parameters
        ----------
        n : int
            Number of radii, a positive integer.
        rng : numpy.random.Generator, optional
            Draws the offset u in [0, 1); without it u = 1/2.

        Returns
        -------
        numpy.ndarray of float, shape (n,)
            The radii, ascending.

        Raises
        ------
        InvalidInputError
            If ``n`` is not a positive integer.
        """
        return np.asarray(self.ppf(_systematic_u(n, rng)), dtype=float)

    def moments(self, kmax: int = 5) -> np.ndarray:
        """Raw moments <a^k> for k = 0..kmax.

        Parameters
        ----------
        kmax : int, default 5
            Highest order.

        Returns
        -------
        numpy.ndarray of float, shape (kmax + 1,)
            <a^0> = 1, <a>, ..., <a^kmax>.
        """
        return np.array([self.moment(k) for k in range(kmax + 1)])

    def params(self) -> dict:
        """Parameters as a flat dict (stored in dataset attributes).

        Returns
        -------
        dict
            The constructor arguments by name.
        """
        raise NotImplementedError


@dataclass(frozen=True)
class Discrete(Distribution):
    """A finite mixture: radii a_s with number fractions n_s (sum 1).

    Parameters
    ----------
    radii : sequence of float
        Species radii a_s, positive and finite; stored sorted ascending.
    fractions : sequence of float
        Number fractions n_s of the species, non-negative, summing to 1; stored in the order of
        the sorted radii.

    Raises
    ------
    InvalidInputError
        If radii and fractions are not 1-d of equal non-zero length, a radius is not positive and
        finite, or the fractions are negative or do not sum to 1.
    """

    radii: tuple
    fractions: tuple
    name = "discrete"

    def __post_init__(self):
        r = np.asarray(self.radii, float)
        f = np.asarray(self.fractions, float)
        if r.ndim != 1 or r.shape != f.shape or r.size == 0:
            raise InvalidInputError(
                f"radii and fractions must be 1-d sequences of equal length, got {r.shape} and {f.shape}"
            )
        if not (np.isfinite(r).all() and (r > 0).all()):
            raise InvalidInputError(f"species radii must be positive and finite, got {r.tolist()}")
        if not (np.isfinite(f).all() and (f >= 0).all() and abs(f.sum() - 1) < 1e-9):
            raise InvalidInputError(
                f"number fractions must be non-negative and sum to 1, got {f.tolist()} (sum {f.sum()})"
            )
        order = np.argsort(r)
        object.__setattr__(self, "radii", tuple(r[order].tolist()))
        object.__setattr__(self, "fractions", tuple(f[order].tolist()))

    def moment(self, k: float) -> float:
        """Raw moment <a^k> = sum_s n_s a_s^k.

        See :meth:`Distribution.moment` for the parameters and the return value.
        """
        r, f = np.asarray(self.radii), np.asarray(self.fractions)
        return float(np.sum(f * r**k))

    def ppf(self, q):
        """Quantile function: the radius of the first species whose cumulative fraction exceeds q.

        See :meth:`Distribution.ppf` for the parameters and the return value.
        """
        cum = np.cumsum(self.fractions)
        cum[-1] = 1.0
        idx = np.searchsorted(cum, np.asarray(q, float), side="right")
        return np.asarray(self.radii)[np.minimum(idx, len(cum) - 1)]

    def pdf(self, a):
        """A discrete mixture has no density: always raises.

        See :meth:`Distribution.pdf` for the parameters and the return value.

        Raises
        ------
        InvalidInputError
            Always; use ``radii`` and ``fractions``.
        """
        raise InvalidInputError("a discrete mixture has no density; use radii and fractions")

    @property
    def support(self):
        return (self.radii[0], self.radii[-1])

    def species_of(self, radii: np.ndarray) -> np.ndarray:
        """Species index (0 = smallest) of each sampled radius.

        Parameters
        ----------
        radii : numpy.ndarray of float, shape (N,)
            Radii equal to species radii (e.g. from :meth:`sample`); any other value gets its
            insertion index in the ascending species radii.

        Returns
        -------
        numpy.ndarray of int32, shape (N,)
            The species indices.
        """
        return np.searchsorted(np.asarray(self.radii), radii).astype(np.int32)

    def params(self):
        """Parameters as a flat dict (stored in dataset attributes).

        See :meth:`Distribution.params` for the parameters and the return value.
        """
        return {"radii": list(self.radii), "fractions": list(self.fractions)}


def monodisperse(radius: float = 1.0) -> Discrete:
    """All spheres of one radius.

    Parameters
    ----------
    radius : float, default 1.0
        The radius, positive and finite.

    Returns
    -------
    Discrete
        A mixture of one species.

    Raises
    ------
    InvalidInputError
        If the radius is not positive and finite.
    """
    return Discrete((float(radius),), (1.0,))


def bidisperse(size_ratio: float, large_fraction: float, mean_radius: float = 1.0) -> Discrete:
    """Binary mixture of a small and a large species (Ogarko's R and n_1; Donev's kappa and x).

    Parameters
    ----------
    size_ratio : float
        a_large / a_small, finite and >= 1.
    large_fraction : float
        Number fraction of the large species, in [0, 1].
    mean_radius : float, default 1.0
        Mean radius <a> the mixture is scaled to.

    Returns
    -------
    Discrete
        The two species, small first.

    Raises
    ------
    InvalidInputError
        If size_ratio is below 1 or not finite, large_fraction is outside [0, 1], or the scaled
        radii are not positive and finite (mean_radius).
    """
    if not (size_ratio >= 1 and math.isfinite(size_ratio)):
        raise InvalidInputError(f"size_ratio must be >= 1 (large / small radius), got {size_ratio}")
    if not 0 <= large_fraction <= 1:
        raise InvalidInputError(f"large_fraction must be in [0, 1], got {large_fraction}")
    mean = large_fraction * size_ratio + (1 - large_fraction)
    small = mean_radius / mean
    return Discrete((small, small * size_ratio), (1 - large_fraction, large_fraction))


@dataclass(frozen=True)
class PowerLaw(Distribution):
    """f(a) = C a^alpha on [a_min, omega a_min], scaled so that <a> = mean_radius (Ogarko 2014,
    Eq. 2.37).

    Parameters
    ----------
    omega : float
        Width a_max / a_min, finite and > 1.
    alpha : float
        Exponent, finite (0: uniform in size; -3: uniform volume).
    mean_radius : float, default 1.0
        Mean radius <a>, positive.

    Raises
    ------
    InvalidInputError
        If omega is not a finite number > 1, alpha is not finite, or mean_radius is not positive.
    """

    omega: float
    alpha: float
    mean_radius: float = 1.0
    name = "power_law"

    def __post_init__(self):
        if not (math.isfinite(self.omega) and self.omega > 1):
            raise InvalidInputError(
                f"omega = a_max / a_min must be > 1 for a power law (use monodisperse for 1), got {self.omega}"
            )
        if not math.isfinite(self.alpha):
            raise InvalidInputError(f"alpha must be finite, got {self.alpha}")
        if not self.mean_radius > 0:
            raise InvalidInputError(f"mean_radius must be positive, got {self.mean_radius}")

    def _unit_moment(self, k: float) -> float:
        """<a^k> for a_min = 1."""
        def integral(p):  # int_1^omega a^p da
            if abs(p + 1) < 1e-12:
                return math.log(self.omega)
            return (self.omega ** (p + 1) - 1) / (p + 1)
        return integral(k + self.alpha) / integral(self.alpha)

    @property
    def a_min(self) -> float:
        return self.mean_radius / self._unit_moment(1)

    def moment(self, k: float) -> float:
        """Raw moment <a^k> = a_min^k int_1^omega x^(k + alpha) dx / int_1^omega x^alpha dx.

        See :meth:`Distribution.moment` for the parameters and the return value.
        """
        return self.a_min**k * self._unit_moment(k)

    @property
    def support(self):
        return (self.a_min, self.omega * self.a_min)

    def pdf(self, a):
        """Normalised density f(a) = a^alpha / int_{a_min}^{a_max} x^alpha dx on the support.

        See :meth:`Distribution.pdf` for the parameters and the return value.
        """
        a = np.asarray(a, float)
        lo, hi = self.support
        p = self.alpha + 1
        if abs(p) < 1e-12:
            norm = math.log(hi / lo)
        else:
            norm = (hi**p - lo**p) / p
        return np.where((a >= lo) & (a <= hi), a**self.alpha / norm, 0.0)

    def ppf(self, q):
        """Quantile function F^-1(q) = (a_min^p + q (a_max^p - a_min^p))^(1/p), p = alpha + 1
        (a_min (a_max / a_min)^q for p = 0).

        See :meth:`Distribution.ppf` for the parameters and the return value.
        """
        q = np.asarray(q, float)
        lo, hi = self.support
        p = self.alpha + 1
        if abs(p) < 1e-12:
            return lo * (hi / lo) ** q
        return (lo**p + q * (hi**p - lo**p)) ** (1 / p)

    def params(self):
        """Parameters as a flat dict (stored in dataset attributes).

        See :meth:`Distribution.params` for the parameters and the return value.
        """
        return {"omega": self.omega, "alpha": self.alpha, "mean_radius": self.mean_radius}


def uniform_size(omega: float, mean_radius: float = 1.0) -> PowerLaw:
    """US: radii uniform on [a_min, omega a_min] (Ogarko 2014, ch. 3, Eq. 3.23 for its moments).

    Parameters
    ----------
    omega : float
        Width a_max / a_min, finite and > 1.
    mean_radius : float, default 1.0
        Mean radius <a>, positive.

    Returns
    -------
    PowerLaw
        The power law with alpha = 0.

    Raises
    ------
    InvalidInputError
        As :class:`PowerLaw`.
    """
    return PowerLaw(omega, 0.0, mean_radius)


def uniform_volume(omega: float, mean_radius: float = 1.0) -> PowerLaw:
    """UV: f(a) ~ a^-3 on [a_min, omega a_min] (Ogarko 2014, Eq. 3.43).

    Parameters
    ----------
    omega : float
        Width a_max / a_min, finite and > 1.
    mean_radius : float, default 1.0
        Mean radius <a>, positive.

    Returns
    -------
    PowerLaw
        The power law with alpha = -3.

    Raises
    ------
    InvalidInputError
        As :class:`PowerLaw`.
    """
    return PowerLaw(omega, -3.0, mean_radius)


@dataclass(frozen=True)
class LogNormal(Distribution):
    """Log-normal radii (Eq. 3.46), a0 = mean_radius exp(-sigma^2 / 2) so that <a> = mean_radius.

    The distribution is unbounded; systematic sampling of n radii reaches the quantile
    1 - 1/(2n) at most, so the sampled moments converge from below as n grows.

    Parameters
    ----------
    sigma : float
        Standard deviation of ln a, finite and > 0.
    mean_radius : float, default 1.0
        Mean radius <a>, positive.

    Raises
    ------
    InvalidInputError
        If sigma is not a finite number > 0 or mean_radius is not positive.
    """

    sigma: float
    mean_radius: float = 1.0
    name = "lognormal"

    def __post_init__(self):
        if not (math.isfinite(self.sigma) and self.sigma > 0):
            raise InvalidInputError(
                f"sigma must be positive (use monodisperse for sigma = 0), got {self.sigma}"
            )
        if not self.mean_radius > 0:
            raise InvalidInputError(f"mean_radius must be positive, got {self.mean_radius}")

    @property
    def a0(self) -> float:
        return self.mean_radius * math.exp(-0.5 * self.sigma**2)

    def moment(self, k: float) -> float:
        """Raw moment <a^k> = a0^k exp(k^2 sigma^2 / 2) (Ogarko 2014, Eq. 3.47).

        See :meth:`Distribution.moment` for the parameters and the return value.
        """
        return self.a0**k * math.exp(0.5 * k * k * self.sigma**2)

    def _dist(self):
        from scipy import stats  # scipy.stats takes ~1 s to import: only when a frozen law is asked for

        return stats.lognorm(s=self.sigma, scale=self.a0)

    def pdf(self, a):
        """Density f(a) of Ogarko 2014, Eq. 3.46 (``scipy.stats.lognorm`` with s = sigma, scale = a0).

        See :meth:`Distribution.pdf` for the parameters and the return value.
        """
        return self._dist().pdf(a)

    def ppf(self, q):
        """Quantile function F^-1(q) = a0 exp(sigma sqrt(2) erfinv(2 q - 1)).

        See :meth:`Distribution.ppf` for the parameters and the return value.
        """
        from scipy.special import erfinv  # scipy costs every importer of this module 0.3 s

        return self.a0 * np.exp(self.sigma * math.sqrt(2) * erfinv(2 * np.asarray(q, float) - 1))

    @property
    def support(self):
        return (0.0, math.inf)

    def params(self):
        """Parameters as a flat dict (stored in dataset attributes).

        See :meth:`Distribution.params` for the parameters and the return value.
        """
        return {"sigma": self.sigma, "mean_radius": self.mean_radius}


def from_spec(spec: dict) -> Distribution:
    """Build a distribution from a config mapping such as ``{"kind": "uniform_volume", "omega": 4}``.

    Parameters
    ----------
    spec : dict
        ``kind`` and that kind's keys: monodisperse; bidisperse (size_ratio, large_fraction);
        uniform_size (omega); uniform_volume (omega); power_law (omega, alpha); lognormal
        (sigma); discrete (radii, fractions). Values are numbers (lists of numbers for radii and
        fractions).

    Returns
    -------
    Distribution
        The distribution; mean radius 1 except for discrete, which keeps the radii given
        (monodisperse of radius 1 for uniform_size or uniform_volume with omega = 1).

    Raises
    ------
    InvalidInputError
        If spec is not a mapping with a known ``kind``, has a key the kind does not take or lacks
        one it needs (the key is named), a value is not a number (or list of numbers), or the
        distribution refuses its parameters.
    """
    if not isinstance(spec, dict) or "kind" not in spec:
        raise InvalidInputError(f"a distribution spec must be a mapping with a 'kind', got {spec!r}")
    kind = spec["kind"]
    allowed = {
        "monodisperse": ((), monodisperse),
        "bidisperse": (("size_ratio", "large_fraction"), bidisperse),
        "uniform_size": (("omega",), uniform_size),
        "uniform_volume": (("omega",), uniform_volume),
        "power_law": (("omega", "alpha"), PowerLaw),
        "lognormal": (("sigma",), LogNormal),
        "discrete": (("radii", "fractions"), Discrete),
    }
    if kind not in allowed:
        raise InvalidInputError(f"unknown distribution kind {kind!r}; choose one of {sorted(allowed)}")
    keys, ctor = allowed[kind]
    extra = set(spec) - set(keys) - {"kind"}
    if extra:
        raise InvalidInputError(
            f"distribution {kind!r} does not take key(s) {sorted(extra)}; it takes {list(keys)}"
        )
    missing = [k for k in keys if k not in spec]
    if missing:
        raise InvalidInputError(f"distribution {kind!r} needs key(s) {missing}")
    for key in keys:
        value = spec[key]
        numbers = value if isinstance(value, (list, tuple)) else [value]
        if not numbers or any(isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating))
                              for v in numbers):
            raise InvalidInputError(
                f"distribution {kind!r}: {key} must be "
                f"{'a list of numbers' if key in ('radii', 'fractions') else 'a number'}, got {value!r} "
                "(write numbers without quotes in JSON)"
            )
    if kind == "monodisperse":
        return monodisperse()
    args = [tuple(spec[k]) if isinstance(spec[k], list) else spec[k] for k in keys]
    if kind in ("uniform_size", "uniform_volume") and float(spec["omega"]) == 1.0:
        return monodisperse()
    return ctor(*args)
