"""Jamming density of nearly circular ellipses from the self-stress of a jammed disk packing.

Donev 2006, dissertation sec. 5.9.2.1 (Eqs. 5.27-5.29): make every disk of a jammed packing an
ellipse of aspect ratio alpha = 1 + eps by shrinking it by the factor 1 / (1 + eps) along one
axis, at angle phi_i + pi/2 (its long semiaxis, the disk radius O_i, stays at angle phi_i). To
first order in eps the contact normals do not move, so the backbone's self-stress F (force
balance) is known a priori, and the density gained by regrowing all particles by a common factor
1 + dmu follows from it.

Derivation (ours; the printed equations are garbled in the text and drop the size weights):

- Shrinking particle i opens its contact with j along the unit vector u_ij = (cos theta, sin
  theta) by eps O_i sin^2(phi_i - theta_ij) (the support function of the ellipse in the direction
  u is O_i (1 - eps sin^2(phi_i - theta)) to first order); regrowing by 1 + dmu closes each gap
  by dmu (O_i + O_j).
- The contacts stay closed for some displacement of the centres iff the gap changes are
  orthogonal to every self-stress (A F = 0, so F^T A^T dr = 0), which for an isostatic backbone
  (one self-stress) gives
  dmu = eps sum_c F_c (O_i s_i + O_j s_j) / sum_c F_c (O_i + O_j), s_i = sin^2(phi_i - theta_ij).
- The area of each particle changes by (1 + dmu)^2 / (1 + eps), so phi_J / phi_SJ = 1 + s_phi eps
  with s_phi = 2 dmu / eps - 1 (Eq. 5.29).
- Torque balance (Eq. 5.27) is the stationarity of sum_j F_ij sin^2(phi_i - theta_ij) in phi_i;
  its maximum is at 2 phi_i = arg(-C_i), C_i = sum_j F_ij exp(2 i theta_ij) (Eq. 5.28 with the
  minus signs), where the sum equals (F_i + |C_i|) / 2 with F_i = sum_j F_ij. Hence

      s_phi = sum_i O_i |C_i| / sum_i O_i F_i,

  in [0, 1]. A random orientation gives zero expected change, and a common orientation phi (the
  affine, nematic deformation) gives s = 2 e^T sigma e / tr sigma - 1 with e the shrunk axis and
  sigma = sum_c F_c (O_i + O_j) u u^T, zero for an isotropic stress.

The printed Eq. 5.29, s_phi = 2 sum_i sum_j f_ij u^T T_i u / sum_i sum_j f_ij - 1, is this result
for equal radii; for unequal radii the derivation weights each end of a contact by its radius
(Donev's f are conjugate to the overlap potential, f ~ F (O_i + O_j) / 2, and his S_ij =
(O_i T_i + O_j T_j) / (O_i + O_j), Sec. 2.2.6, carry the same weights). Donev reports
s_phi ~ 0.454 for disordered binary disk packings at phi_SJ ~ 0.84.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError


@dataclass(frozen=True)
class EllipseSlope:
    """First-order jamming density of ellipses near the disk point (module docstring).

    Attributes
    ----------
    slope : float
        s_phi of phi_J / phi_SJ = 1 + s_phi (alpha - 1) at the torque-balancing orientations.
    angles : numpy.ndarray, shape (N,)
        phi_i in [-pi/2, pi/2): the long axis of each ellipse (NaN for particles without loaded
        contacts, whose orientation does not matter).
    n_loaded : int
        Particles that carry force.
    """

    slope: float
    angles: np.ndarray
    n_loaded: int


def _weights(separation, i, j, forces, radii):
    sep = np.asarray(separation, float)
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    f = np.asarray(forces, float)
    radii = np.asarray(radii, float)
    m = len(f)
    if sep.ndim != 2 or sep.shape != (m, 2) or i.shape != (m,) or j.shape != (m,):
        raise InvalidInputError(
            "ellipse slope: separation must have shape (M, 2) and i, j, forces shape (M,) for M "
            f"contacts of a 2D packing; got {sep.shape}, {i.shape}, {j.shape}, {f.shape}")
    if not (np.all(np.isfinite(sep)) and np.all(np.isfinite(f)) and np.all(np.isfinite(radii))):
        raise InvalidInputError("ellipse slope: separations, forces and radii must be finite")
    if (f < 0).any():
        raise InvalidInputError("ellipse slope: contact forces must be non-negative (a self-stress of hard particles)")
    n = len(radii)
    if m and (min(i.min(), j.min()) < 0 or max(i.max(), j.max()) >= n):
        raise InvalidInputError(f"ellipse slope: contact indices must lie in [0, {n}) for {n} radii")
    phase = np.exp(2j * np.arctan2(sep[:, 1], sep[:, 0]))  # u_ji = -u_ij has the same 2 theta
    c = np.zeros(n, complex)
    total = np.zeros(n)
    np.add.at(c, i, f * phase)
    np.add.at(c, j, f * phase)
    np.add.at(total, i, f)
    np.add.at(total, j, f)
    return c, total, radii


def ellipse_slope(separation, i, j, forces, radii) -> EllipseSlope:
    """s_phi and the torque-balancing orientations of Donev 2006, Eqs. 5.28-5.29 (module docstring).

    Parameters
    ----------
    separation : array_like, shape (M, 2)
        r_ij = x_j - x_i (nearest image) of every contact.
    i, j : array_like of int, shape (M,)
        The particles of every contact.
    forces : array_like, shape (M,)
        A self-stress (non-negative, balanced at every particle), e.g. the backbone forces of
        :func:`hardpack.jamming.verify`; its normalisation does not matter.
    radii : array_like, shape (N,)
        The disk radii O_i.

    Returns
    -------
    EllipseSlope
        The slope (NaN when no contact carries force), orientations and loaded-particle count.

    Raises
    ------
    InvalidInputError
        On wrong shapes, non-finite values, negative forces or indices out of range.
    """
    c, total, radii = _weights(separation, i, j, forces, radii)
    loaded = total > 0
    denominator = float(np.sum(radii * total))
    slope = float(np.sum(radii * np.abs(c)) / denominator) if denominator > 0 else float("nan")
    angles = np.where(loaded, 0.5 * np.angle(-c), np.nan)
    angles = np.where(angles >= 0.5 * np.pi, angles - np.pi, angles)
    return EllipseSlope(slope, angles, int(loaded.sum()))


def slope_at_angles(separation, i, j, forces, radii, angles) -> float:
    """s = 2 dmu / eps - 1 for given long-axis angles phi_i (module docstring): the density slope
    of any orientation assignment, of which :func:`ellipse_slope` is the maximum.

    Parameters
    ----------
    separation, i, j, forces, radii
        As in :func:`ellipse_slope`.
    angles : array_like, shape (N,)
        Long-axis angle of every particle (radians; ignored for unloaded particles).

    Returns
    -------
    float
        The slope, NaN when no contact carries force.
    """
    sep = np.asarray(separation, float)
    f = np.asarray(forces, float)
    _weights(sep, i, j, f, radii)  # validation
    radii = np.asarray(radii, float)
    angles = np.nan_to_num(np.asarray(angles, float))
    theta = np.arctan2(sep[:, 1], sep[:, 0])
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    gain = radii[i] * np.sin(angles[i] - theta) ** 2 + radii[j] * np.sin(angles[j] - theta) ** 2
    denominator = float(np.sum(f * (radii[i] + radii[j])))
    return 2.0 * float(np.sum(f * gain)) / denominator - 1.0 if denominator > 0 else float("nan")
