"""Particle shapes: one description per particle, with its volume and bounding radius.

A packing holds one shape object for all its particles; its ``kind`` names the model:

- ``"sphere"`` (:class:`Spheres`): a radius per particle (d = 1..12).
- ``"ellipsoid"`` (:class:`Ellipsoids`, d = 2 or 3): semiaxes per particle, given in the body
  frame, and an orientation. The particle is the set (r - r0)^T X (r - r0) <= 1 with
  X = Q^T O^-2 Q, O = diag(semiaxes) (Donev 2006, Sec. 2.2, Eqs. 2.7-2.8), where Q is the
  rotation matrix of the orientation (Donev 2006, Sec. 1.4.3):

  - 3D: a unit quaternion w = [s, p] = [cos(phi/2), sin(phi/2) n] for a rotation by phi about the
    unit axis n (Eq. 1.7), stored as (s, p_1, p_2, p_3); Q = 2 [p p^T - s P + (s^2 - 1/2) I]
    with P the cross-product matrix of p.
  - 2D: the angle phi between the first semiaxis and the x axis (the unit complex number
    [cos phi, sin phi] of Eq. 1.8); Q = [[cos phi, sin phi], [-sin phi, cos phi]].

  Q maps lab-frame vectors to the body frame: its rows are the body axes in the lab frame, and the
  reference orientation (w = [1, 0, 0, 0], phi = 0) has the semiaxes along the coordinate axes.
  A sphere of radius a is the ellipsoid with all semiaxes a (X = I / a^2).

Volumes: V_d(1) prod_k a_k (pi a b in 2D, 4/3 pi a b c in 3D). The bounding radius (the largest
semiaxis, Donev 2006, Sec. 2.3) is what neighbour search and cell sizes use.

A later kind fits the same interface (``kind``, ``name``, ``n_particles``, ``dim``,
``volumes``, ``bounding_radii``, ``take``): superellipsoids (Donev 2006, Sec. 2.3) add an exponent
per particle to the ellipsoid's semiaxes and orientation, with volume prod_k a_k K_d(eps).

Every array is validated on construction (finite, right shape, positive semiaxes, unit
quaternions) and stored read-only. Quaternions are kept bit for bit when their norm is 1 to
round-off (|w| - 1 within 8 machine epsilons), normalised when it is within
``QUATERNION_TOL`` (e.g. after many compositions, Donev 2006, Algorithm 1), and refused otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume, unit_ball_volume

QUATERNION_TOL = 1e-10
_UNIT_ROUNDOFF = 8 * np.finfo(float).eps
ELLIPSOID_DIMS = (2, 3)


def as_finite_array(name: str, value, shape_hint: str) -> np.ndarray:
    """``value`` as a new float array; refuses non-numeric and non-finite entries, naming ``name``.

    Parameters
    ----------
    name : str
        Name of the argument, for the error message.
    value : array_like
        The value.
    shape_hint : str
        Expected shape, for the error message.

    Returns
    -------
    numpy.ndarray of float
        A copy of ``value``.

    Raises
    ------
    InvalidInputError
        For non-numeric or non-finite entries.
    """
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be numeric with shape {shape_hint}: {exc}") from None
    bad = ~np.isfinite(arr)
    if bad.any():
        where = np.argwhere(bad)[0].tolist()
        raise InvalidInputError(
            f"{name} contains a non-finite value (NaN or inf) at index {where}; "
            "every entry must be a finite number"
        )
    return arr


def _freeze(obj, **arrays) -> None:
    for name, arr in arrays.items():
        arr.setflags(write=False)
        object.__setattr__(obj, name, arr)


@dataclass(frozen=True, eq=False)
class Spheres:
    """Hard spheres: ``radii`` of shape (N,), positive and finite.

    Parameters
    ----------
    radii : array_like, shape (N,)
        One positive finite radius per particle; stored as a read-only float array.

    Raises
    ------
    InvalidInputError
        If ``radii`` is not numeric, not finite, not of shape (N,) or not positive.
    """

    radii: np.ndarray
    kind: ClassVar[str] = "sphere"
    name: ClassVar[str] = "hard spheres"
    dim: ClassVar[None] = None  # any dimension

    def __post_init__(self):
        radii = as_finite_array("radii", self.radii, "(N,)")
        if radii.ndim != 1:
            raise InvalidInputError(
                f"radii must have shape (N,), one radius per particle, got shape {radii.shape}"
            )
        if (radii <= 0).any():
            i = int(np.argmin(radii))
            raise InvalidInputError(f"radii must be positive; particle {i} has radius {float(radii[i])!r}")
        _freeze(self, radii=radii)

    @property
    def n_particles(self) -> int:
        return len(self.radii)

    def volumes(self, d: int) -> np.ndarray:
        """Volume of every particle in d dimensions, V_d(r_i).

        Parameters
        ----------
        d : int
            Dimension.

        Returns
        -------
        numpy.ndarray of float, shape (N,)
            The volumes.
        """
        return ball_volume(self.radii, d)

    @property
    def bounding_radii(self) -> np.ndarray:
        return self.radii

    def take(self, index) -> Spheres:
        """The particles ``index`` (an integer or boolean array), in that order.

        Parameters
        ----------
        index : int array_like or numpy.ndarray of bool, shape (N,)
            Indices (repeats allowed) or a mask.

        Returns
        -------
        Spheres
            The selected particles.
        """
        return Spheres(self.radii[index])

    def __repr__(self) -> str:
        return f"Spheres(N={self.n_particles}, radii=[{self.radii.min():.4g}, {self.radii.max():.4g}])"


@dataclass(frozen=True, eq=False)
class Ellipsoids:
    """Hard ellipsoids (d = 3) or ellipses (d = 2); conventions in the module docstring.

    ``semiaxes`` (N, d): positive body-frame semiaxes. ``orientations``: (N, 4) unit quaternions
    (s, p_1, p_2, p_3) in 3D, (N,) angles in radians in 2D.

    Parameters
    ----------
    semiaxes : array_like, shape (N, d), d in (2, 3)
        Positive finite body-frame semiaxes of each particle.
    orientations : array_like, shape (N, 4) in 3D or (N,) in 2D
        Unit quaternions (s, p_1, p_2, p_3) (Donev 2006, Eq. 1.7) or angles in radians of the
        first semiaxis with the x axis. A quaternion within 8 machine epsilons of unit norm is
        kept as given, one within ``QUATERNION_TOL`` is normalised.

    Raises
    ------
    InvalidInputError
        If the arrays are not numeric and finite, have the wrong shapes, a semiaxis is not
        positive, or a quaternion's norm is off 1 by more than ``QUATERNION_TOL``.
    """

    semiaxes: np.ndarray
    orientations: np.ndarray
    kind: ClassVar[str] = "ellipsoid"

    def __post_init__(self):
        axes = as_finite_array("semiaxes", self.semiaxes, "(N, d)")
        if axes.ndim != 2 or axes.shape[1] not in ELLIPSOID_DIMS:
            raise InvalidInputError(
                f"semiaxes must have shape (N, d) with d in {ELLIPSOID_DIMS} (ellipses or "
                f"ellipsoids), got shape {axes.shape}"
            )
        if (axes <= 0).any():
            i, k = np.argwhere(axes <= 0)[0]
            raise InvalidInputError(
                f"semiaxes must be positive; particle {i} has semiaxis {k} = {float(axes[i, k])!r}"
            )
        n, d = axes.shape
        _freeze(self, semiaxes=axes, orientations=_orientations(self.orientations, n, d))

    @property
    def n_particles(self) -> int:
        return self.semiaxes.shape[0]

    @property
    def dim(self) -> int:
        return self.semiaxes.shape[1]

    @property
    def name(self) -> str:
        return "hard ellipses" if self.dim == 2 else "hard ellipsoids"

    def volumes(self, d: int) -> np.ndarray:
        """Volume of every particle, V_d(1) prod_k a_k (pi a b in 2D, 4/3 pi a b c in 3D).

        Parameters
        ----------
        d : int
            Dimension (the shape's own, :attr:`dim`).

        Returns
        -------
        numpy.ndarray of float, shape (N,)
            The volumes.
        """
        return unit_ball_volume(d) * np.prod(self.semiaxes, axis=1)

    @property
    def bounding_radii(self) -> np.ndarray:
        """Largest semiaxis: the radius of the smallest ball about the centre that holds the particle."""
        return self.semiaxes.max(axis=1)

    def rotations(self) -> np.ndarray:
        """Rotation matrices Q (N, d, d), lab to body frame (module docstring, Donev 2006 Sec. 1.4.3)."""
        if self.dim == 2:
            c, s = np.cos(self.orientations), np.sin(self.orientations)
            return np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], -2)
        s, p = self.orientations[:, 0], self.orientations[:, 1:]
        cross = np.zeros((len(s), 3, 3))
        cross[:, 0, 1], cross[:, 0, 2], cross[:, 1, 2] = -p[:, 2], p[:, 1], -p[:, 0]
        cross -= cross.transpose(0, 2, 1)
        return 2.0 * (p[:, :, None] * p[:, None, :] - s[:, None, None] * cross
                      + (s**2 - 0.5)[:, None, None] * np.eye(3))

    def shape_matrices(self) -> np.ndarray:
        """X = Q^T O^-2 Q (N, d, d): the particle is (r - r0)^T X (r - r0) <= 1 (Donev 2006, Eq. 2.8)."""
        q = self.rotations()
        return np.einsum("nki,nk,nkj->nij", q, self.semiaxes**-2.0, q)

    def take(self, index) -> Ellipsoids:
        """The particles ``index`` (an integer or boolean array), in that order.

        Parameters
        ----------
        index : int array_like or numpy.ndarray of bool, shape (N,)
            Indices (repeats allowed) or a mask.

        Returns
        -------
        Ellipsoids
            The selected particles with their semiaxes and orientations.
        """
        return Ellipsoids(self.semiaxes[index], self.orientations[index])

    def __repr__(self) -> str:
        return (f"Ellipsoids(N={self.n_particles}, d={self.dim}, semiaxes=[{self.semiaxes.min():.4g}, "
                f"{self.semiaxes.max():.4g}])")


def _orientations(value, n: int, d: int) -> np.ndarray:
    """Validated orientations of n ellipsoids in d dimensions (angles in 2D, unit quaternions in 3D)."""
    if d == 2:
        angles = as_finite_array("orientations", value, "(N,) (one angle per ellipse)")
        if angles.shape != (n,):
            raise InvalidInputError(
                f"orientations of {n} ellipses must be {n} angles (radians), shape ({n},), "
                f"got shape {angles.shape}"
            )
        return angles
    quat = as_finite_array("orientations", value, "(N, 4) (one unit quaternion per ellipsoid)")
    if quat.shape != (n, 4):
        raise InvalidInputError(
            f"orientations of {n} ellipsoids must be unit quaternions (s, p1, p2, p3), shape "
            f"({n}, 4), got shape {quat.shape}"
        )
    norm = np.sqrt(np.einsum("ij,ij->i", quat, quat))
    off = np.abs(norm - 1.0)
    if (off > QUATERNION_TOL).any():
        i = int(np.argmax(off))
        raise InvalidInputError(
            f"orientations must be unit quaternions; particle {i} has {quat[i].tolist()} of norm "
            f"{norm[i]:.17g} (|w| must be 1 within {QUATERNION_TOL:g}). Divide it by its norm if "
            "it is meant as that rotation"
        )
    renorm = off > _UNIT_ROUNDOFF
    if renorm.any():
        quat[renorm] /= norm[renorm, None]
    return quat
