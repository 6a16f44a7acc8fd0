"""Freezing of a binary hard-disk liquid into a crystal of the pure large disks, by matching the
large disks' chemical potential in the two phases at equal pressure (Donev 2006, sec. 13.2,
Eq. 13.2; the crystal is assumed fully phase-separated, no solubility).

Species A (small, diameter 1, volume v_A) and B (large, diameter kappa), number fractions x_A,
x_B = 1 - x_A, kT = 1, D = disk dimension d. With Delta f the excess free energy over the ideal
gas per particle (:mod:`hardpack.glass.thermo`) and Z the reduced pressure, the chemical
potentials, with the common -ln v_A dropped, are (derived here from mu_B = dF/dN_B at fixed V,
N_A; the printed form of sec. 13.2 is scrambled in the text and agrees with this one):

- pure B at phi_B:
  mu_B = ln phi_B - d ln kappa - 1 + Delta f_B(phi_B) + Z_B(phi_B)
- B in the mixture at phi (v = x_A + x_B kappa^d, the mean volume in units of v_A):
  mu_AB = ln phi + ln(x_B / v) + Delta f_AB(phi) + (Z_AB(phi) - 1) kappa^d / v - x_A mu~_B(phi),
  mu~_B = (d Delta f_AB / d x_A) at fixed phi.

The monodisperse free energy is scale free, so Delta f_B and Z_B are those of monodisperse disks
(:func:`hardpack.glass.thermo.excess_free_energy` of their EOS). Equal pressures (P v_A):
pi = phi_B Z_B(phi_B) / kappa^d = phi Z_AB(phi) / v. Freezing is the pressure where
mu_AB = mu_B; below it the liquid is stable (mu_AB < mu_B), above it the large disks precipitate.

Check (in the tests): for an ideal gas (Z = 1, Delta f = 0) mu_AB - mu_B = ln x_B exactly, at
every pressure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from hardpack.errors import InvalidInputError

Function = Callable[[float], float]


@dataclass(frozen=True)
class Phase:
    """An EOS as functions of phi on [phi_lo, phi_hi]: Z(phi) and Delta f(phi).

    Attributes
    ----------
    z : callable
        phi -> reduced pressure Z.
    excess : callable
        phi -> excess free energy per particle Delta f (units of kT).
    phi_lo, phi_hi : float
        The range of phi.
    """

    z: Function
    excess: Function
    phi_lo: float
    phi_hi: float


@dataclass(frozen=True)
class Mixture:
    """A binary disk mixture: diameter ratio kappa (large / small), number fraction x_B of the
    large disks, dimension d.

    Attributes
    ----------
    kappa : float
        Diameter ratio, >= 1.
    x_large : float
        Number fraction of the large disks, in (0, 1).
    d : int
        Dimension.
    """

    kappa: float
    x_large: float
    d: int = 2

    def __post_init__(self):
        if not self.kappa >= 1.0:
            raise InvalidInputError(f"kappa must be >= 1 (large / small diameter), got {self.kappa}")
        if not 0.0 < self.x_large < 1.0:
            raise InvalidInputError(f"x_large must be in (0, 1), got {self.x_large}")

    @property
    def mean_volume(self) -> float:
        """x_A + x_B kappa^d: the mean particle volume in units of the small one."""
        return (1.0 - self.x_large) + self.x_large * self.kappa**self.d


def mu_pure(phase: Phase, phi_b: float, mix: Mixture) -> float:
    """mu_B of the pure large-disk phase at phi_B (module docstring).

    Parameters
    ----------
    phase : Phase
        EOS of the pure large-disk crystal.
    phi_b : float
        Its volume fraction.
    mix : Mixture
        The mixture (kappa, d).

    Returns
    -------
    float
        mu_B in units of kT (the common -ln v_A dropped).
    """
    return (math.log(phi_b) - mix.d * math.log(mix.kappa) - 1.0 + phase.excess(phi_b) + phase.z(phi_b))


def mu_mixture(phase: Phase, phi: float, mix: Mixture, mu_tilde: Function) -> float:
    """mu_B of the large disks in the mixture at phi (module docstring).

    Parameters
    ----------
    phase : Phase
        EOS of the mixture.
    phi : float
        Its volume fraction.
    mix : Mixture
        The mixture.
    mu_tilde : callable
        phi -> mu~_B(phi) (:func:`composition_derivative`).

    Returns
    -------
    float
        mu_AB in units of kT (the common -ln v_A dropped).
    """
    v = mix.mean_volume
    x_a = 1.0 - mix.x_large
    return (math.log(phi) + math.log(mix.x_large / v) + phase.excess(phi)
            + (phase.z(phi) - 1.0) * mix.kappa**mix.d / v - x_a * mu_tilde(phi))


def _phi_at(phase: Phase, target: float, scale: float) -> float:
    """phi on the phase's range where phi Z(phi) / scale = target (monotone in phi)."""
    def g(p):
        return p * phase.z(p) / scale - target

    lo, hi = phase.phi_lo, phase.phi_hi
    if not g(lo) <= 0 <= g(hi):
        raise InvalidInputError(f"pressure {target:.4g} is outside the EOS range phi in [{lo}, {hi}]")
    return brentq(g, lo, hi, xtol=1e-13)


@dataclass(frozen=True)
class Freezing:
    """The freezing point: the mixture's phi_F and the precipitate's phi_B at pressure pi
    (P v_A / kT), with the chemical potential there.

    Attributes
    ----------
    phi_freeze : float
        Volume fraction phi_F of the mixture.
    phi_precipitate : float
        Volume fraction phi_B of the precipitate.
    pressure : float
        P v_A / kT.
    mu : float
        mu_B = mu_AB there.
    """

    phi_freeze: float
    phi_precipitate: float
    pressure: float
    mu: float


def mu_difference(pressure: float, pure: Phase, mixture: Phase, mix: Mixture, mu_tilde: Function) -> float:
    """mu_AB - mu_B at equal pressure ``pressure`` = P v_A / kT.

    Parameters
    ----------
    pressure : float
        P v_A / kT.
    pure : Phase
        EOS of the pure large-disk crystal.
    mixture : Phase
        EOS of the mixture.
    mix : Mixture
        The mixture.
    mu_tilde : callable
        phi -> mu~_B(phi).

    Returns
    -------
    float
        mu_AB - mu_B in units of kT.
    """
    phi_b = _phi_at(pure, pressure, mix.kappa**mix.d)
    phi = _phi_at(mixture, pressure, mix.mean_volume)
    return mu_mixture(mixture, phi, mix, mu_tilde) - mu_pure(pure, phi_b, mix)


def freezing_point(pure: Phase, mixture: Phase, mix: Mixture, mu_tilde: Function | float = 0.0,
                   n_scan: int = 200) -> Freezing:
    """Solve mu_AB(pi) = mu_B(pi) (Eq. 13.2) over the pressures both EOS cover.

    Parameters
    ----------
    pure : Phase
        Monodisperse disks (the large-disk crystal): Z(phi), Delta f(phi) and the phi range.
    mixture : Phase
        The binary liquid at the composition of ``mix``.
    mix : Mixture
        kappa, x_B and d.
    mu_tilde : callable or float, default 0
        (d Delta f_AB / d x_A) at fixed phi (e.g. :func:`composition_derivative`).
    n_scan : int, default 200
        Pressures scanned (geometrically) for the first sign change before the root is refined.

    Returns
    -------
    Freezing

    Raises
    ------
    InvalidInputError
        If the two EOS share no pressure range or mu_AB - mu_B does not change sign on it (no
        freezing within the data: the message gives the difference at both ends).
    """
    mt = (lambda p, c=float(mu_tilde): c) if np.isscalar(mu_tilde) else mu_tilde
    k_d, v = mix.kappa**mix.d, mix.mean_volume
    lo = max(pure.phi_lo * pure.z(pure.phi_lo) / k_d, mixture.phi_lo * mixture.z(mixture.phi_lo) / v)
    hi = min(pure.phi_hi * pure.z(pure.phi_hi) / k_d, mixture.phi_hi * mixture.z(mixture.phi_hi) / v)
    if not hi > lo:
        raise InvalidInputError(f"the two EOS share no pressure range ({lo:.4g} >= {hi:.4g})")
    grid = np.geomspace(lo, hi, n_scan)
    diff = np.array([mu_difference(p, pure, mixture, mix, mt) for p in grid])
    change = np.flatnonzero(np.sign(diff[:-1]) * np.sign(diff[1:]) <= 0)
    if change.size == 0:
        raise InvalidInputError(
            f"no freezing in the data: mu_AB - mu_B = {diff[0]:.4g} at P v_A = {lo:.4g} and "
            f"{diff[-1]:.4g} at {hi:.4g}")
    k = int(change[0])
    root = brentq(mu_difference, grid[k], grid[k + 1], args=(pure, mixture, mix, mt), xtol=1e-12)
    phi_b = _phi_at(pure, root, k_d)
    return Freezing(_phi_at(mixture, root, v), phi_b, root, mu_pure(pure, phi_b, mix))


@dataclass(frozen=True)
class SeparatedCrystal:
    """The fully phase-separated crystal A + B at overall volume fractions ``phi`` (Donev 2006,
    sec. 13.2.2.1, Fig. 13.4): the densities of the small-disk phase A and the large-disk phase B
    at mechanical equilibrium, the pressure and the overall reduced pressure; NaN where the
    monodisperse EOS does not cover a phase.

    Attributes
    ----------
    phi, phi_a, phi_b, pressure, z : numpy.ndarray
        Overall volume fraction, phase densities, P v_A / kT and Z = P V / (N kT).
    """

    phi: np.ndarray
    phi_a: np.ndarray
    phi_b: np.ndarray
    pressure: np.ndarray
    z: np.ndarray


def separated_crystal(pure: Phase, mix: Mixture, phi) -> SeparatedCrystal:
    """Solve the fully phase-separated crystal (Donev 2006, sec. 13.2.2.1): equal pressures
    phi_A Z(phi_A) = phi_B Z(phi_B) / kappa^d = P v_A / kT and the overall density
    1 / phi = (x_A / v) / phi_A + (x_B kappa^d / v) / phi_B (v = x_A + x_B kappa^d), with Z the
    monodisperse EOS (scale free, so both phases share it). The overall density grows with the
    pressure, so each phi has one root.

    Parameters
    ----------
    pure : Phase
        EOS of monodisperse disks (Z and its range; the excess is not used).
    mix : Mixture
        kappa, x_B and d.
    phi : array_like of float
        Overall volume fractions.

    Returns
    -------
    SeparatedCrystal
        NaN where phi is outside what the EOS's range reaches.
    """
    targets = np.atleast_1d(np.asarray(phi, float))
    k_d, v = mix.kappa**mix.d, mix.mean_volume

    def overall(pressure):
        return _overall_phi(mix, _phi_at(pure, pressure, 1.0), _phi_at(pure, pressure, k_d))

    lo = pure.phi_lo * pure.z(pure.phi_lo)
    hi = pure.phi_hi * pure.z(pure.phi_hi) / k_d
    out = np.full((4, targets.size), np.nan)
    if hi > lo:
        phi_lo, phi_hi = overall(lo), overall(hi)
        for i, target in enumerate(targets):
            if phi_lo <= target <= phi_hi:
                pressure = brentq(lambda p, t=target: overall(p) - t, lo, hi, xtol=1e-13)
                out[:, i] = (_phi_at(pure, pressure, 1.0), _phi_at(pure, pressure, k_d), pressure,
                             pressure * v / target)
    return SeparatedCrystal(targets, *out)


def separated_melting(pure: Phase, mix: Mixture, phi_transition: float) -> tuple[float, float]:
    """The overall densities at which the small-disk phase A and the large-disk phase B of the
    fully phase-separated crystal reach the monodisperse transition density (Donev 2006, sec.
    13.2.2.1: A melts at phi ~ 0.75, B at ~0.65; the caption of Fig. 13.4 swaps the two names).

    The pressure is set by the phase at the transition, P v_A = phi_t Z(phi_t) for A and
    phi_t Z(phi_t) / kappa^d for B, and the other phase's density follows from it. No root is
    taken inside the transition, where a finite system's EOS has a loop.

    Parameters
    ----------
    pure : Phase
        EOS of monodisperse disks.
    mix : Mixture
        kappa, x_B and d.
    phi_transition : float
        The monodisperse transition density (within the range of ``pure``).

    Returns
    -------
    (float, float)
        The overall phi at which A, then B, is at ``phi_transition``.
    """
    if not pure.phi_lo <= phi_transition <= pure.phi_hi:
        raise InvalidInputError(f"phi_transition = {phi_transition} is outside the EOS range "
                                f"[{pure.phi_lo}, {pure.phi_hi}]")
    k_d = mix.kappa**mix.d
    pressure = phi_transition * pure.z(phi_transition)
    a_melts = _overall_phi(mix, phi_transition, _phi_at(pure, pressure, k_d))
    b_melts = _overall_phi(mix, _phi_at(pure, pressure / k_d, 1.0), phi_transition)
    return a_melts, b_melts


def _overall_phi(mix: Mixture, phi_a: float, phi_b: float) -> float:
    """The overall density of the separated phases: 1 / phi = (x_A / v) / phi_A + (x_B kappa^d / v) / phi_B."""
    v = mix.mean_volume
    return 1.0 / ((1.0 - mix.x_large) / v / phi_a + mix.x_large * mix.kappa**mix.d / v / phi_b)


def composition_derivative(excess_plus: Function, excess_minus: Function, dx: float) -> Function:
    """mu~_B(phi) = (d Delta f_AB / d x_A)_phi by the central difference of two mixtures at
    x_A +- dx (thermodynamic integration at slightly different compositions, Donev 2006, sec. 13.2).

    Parameters
    ----------
    excess_plus, excess_minus : callable
        phi -> Delta f of the mixtures at x_A + dx and x_A - dx.
    dx : float
        Composition step, > 0.

    Returns
    -------
    callable
        phi -> mu~_B(phi).
    """
    if not dx > 0:
        raise InvalidInputError(f"dx must be > 0, got {dx}")
    return lambda phi: (excess_plus(phi) - excess_minus(phi)) / (2.0 * dx)


def tabulated_phase(phi, z, excess) -> Phase:
    """A Phase from tabulated phi (increasing), Z and Delta f, interpolated linearly (Z) and by
    integrating the linear interpolant of (Z - 1)/phi between the points (Delta f, consistent
    with :func:`hardpack.glass.thermo.excess_free_energy`).

    Parameters
    ----------
    phi : array_like of float, shape (k,)
        Strictly increasing volume fractions.
    z : array_like of float, shape (k,)
        Reduced pressures.
    excess : array_like of float, shape (k,)
        Delta f at the points.

    Returns
    -------
    Phase
        The interpolated phase on [phi[0], phi[-1]].
    """
    phi, z, excess = (np.asarray(a, float) for a in (phi, z, excess))
    if phi.size < 2 or np.any(np.diff(phi) <= 0):
        raise InvalidInputError("a tabulated phase needs >= 2 strictly increasing phi")
    y = (z - 1.0) / phi

    def z_of(p):
        return float(np.interp(p, phi, z))

    def f_of(p):
        k = int(np.clip(np.searchsorted(phi, p) - 1, 0, phi.size - 2))
        y_p = np.interp(p, phi, y)
        return float(excess[k] + 0.5 * (p - phi[k]) * (y[k] + y_p))

    return Phase(z_of, f_of, float(phi[0]), float(phi[-1]))
