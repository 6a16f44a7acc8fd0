"""Volumes of d-dimensional balls.

V_d(r) = pi^(d/2) / Gamma(d/2 + 1) * r^d   (e.g. Donev dissertation ch. 11; Skoge et al. 2006).
"""

import math

import numpy as np


def unit_ball_volume(d: int) -> float:
    """Volume of the unit ball in d dimensions, pi^(d/2) / Gamma(d/2 + 1)."""
    if int(d) != d or d < 1:
        raise ValueError(f"dimension must be a positive integer, got {d!r}")
    return math.pi ** (d / 2) / math.gamma(d / 2 + 1)


def ball_volume(radius, d: int):
    """Volume of d-balls of the given radius (scalar or array)."""
    return unit_ball_volume(d) * np.asarray(radius, dtype=float) ** d
