"""Volumes of d-dimensional balls.

V_d(r) = pi^(d/2) / Gamma(d/2 + 1) * r^d   (e.g. Donev dissertation ch. 11; Skoge et al. 2006).
"""

import math

import numpy as np


def unit_ball_volume(d: int) -> float:
    """Volume of the unit ball in d dimensions, pi^(d/2) / Gamma(d/2 + 1).

    Parameters
    ----------
    d : int
        The dimension, a positive integer.

    Returns
    -------
    float
        V_d(1) (pi in 2D, 4 pi / 3 in 3D).

    Raises
    ------
    ValueError
        If ``d`` is not a positive integer.
    """
    if int(d) != d or d < 1:
        raise ValueError(f"dimension must be a positive integer, got {d!r}")
    return math.pi ** (d / 2) / math.gamma(d / 2 + 1)


def ball_volume(radius, d: int):
    """Volume of d-balls of the given radius (scalar or array).

    Parameters
    ----------
    radius : float or array_like
        Ball radii (not checked for sign).
    d : int
        The dimension, a positive integer.

    Returns
    -------
    numpy.ndarray or numpy.float64
        V_d(1) radius^d, of the shape of ``radius``.

    Raises
    ------
    ValueError
        If ``d`` is not a positive integer.
    """
    return unit_ball_volume(d) * np.asarray(radius, dtype=float) ** d
