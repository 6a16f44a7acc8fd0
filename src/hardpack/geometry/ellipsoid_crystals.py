"""Unusually dense crystal packings of spheroids: the laminate of Donev 2006, ch. 8 (Sec. 8.2).

Construction (Donev 2006, Sec. 8.2, Eqs. 8.1-8.3; Donev, Stillinger, Chaikin & Torquato, Phys.
Rev. Lett. 92, 255506 (2004)). Start from FCC seen as (001) layers of face-centred squares and
make every sphere a spheroid with semiaxes 1 : alpha : 1, its long axis in the layer:

1. Layer A holds spheroids with the long axis along y at (0, 0, 0) and (L/2, L/2, 0). Diagonal
   neighbours touch when L = 4 alpha / sqrt(1 + alpha^2) (Eq. 8.1; the contact distance of two
   parallel ellipsoids along the unit vector u is 2 / sqrt(u^T X u)). For alpha > sqrt(3) the
   neighbours along y would overlap, so L = 2 alpha there (the unstretched laminate).
2. Layer B, a height z above, holds the same spheroids turned by pi/2 (long axis along x) at
   (L/2, 0, z) and (0, L/2, z), in the holes of layer A; z is the smallest height at which the
   crossed spheroids do not overlap (a root of the Perram-Wertheim contact function,
   :mod:`hardpack.geometry.contact`). The cell is L x L x 2z with 4 particles, so
   phi = 16 pi alpha / (3 (2z) L^2) (Eq. 8.2 with h = 2z, the period of two layers; the text calls
   h the distance between successive layers, which gives twice the density).
3. At alpha = sqrt(3) the y neighbours touch too: 14 contacts per particle and the densest known
   packing, phi = 0.770732. Its affine stretch by a factor s along (1, 1, 0) / sqrt(2) keeps phi
   and makes ellipsoids of in-plane aspect ratio alpha(s) >= sqrt(3) (Eq. 8.3; the semiaxis
   normal to the layers stays 1 and can be rescaled to make spheroids); s = 2.4842 gives
   alpha = 3 (Fig. 8.3).

The perpendicular semiaxis can be rescaled freely without changing phi, and phi(alpha) =
phi(1 / alpha) (Fig. 8.2): only the in-plane ratio matters. At alpha = 1 the laminate is FCC.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from hardpack.errors import InvalidInputError
from hardpack.geometry.contact import pw_contact, shape_inverse
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids

#: relative gap (mu - 1 of the Perram-Wertheim scaling) within which two crystal neighbours touch
CRYSTAL_CONTACT_TOL = 1e-9

#: aspect ratio of the densest laminate, where the in-plane neighbours along the long axis touch
DENSEST_ALPHA = math.sqrt(3.0)

_LONG_Y = np.array([math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)])  # pi/2 about z
_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _inverse(semiaxes, quaternion) -> np.ndarray:
    out = np.empty((3, 3))
    shape_inverse(np.asarray(semiaxes, float), np.asarray(quaternion, float), out)
    return out


def _zeta(offset, a_inv, b_inv) -> float:
    return pw_contact(np.asarray(offset, float), a_inv, b_inv, 0.5)[0]


def square_side(alpha: float) -> float:
    """Side L of the face-centred square layer: Eq. 8.1, or 2 alpha beyond sqrt(3), where the
    neighbours along the long axis touch.

    Parameters
    ----------
    alpha : float
        Aspect ratio of the spheroids (long over short semiaxis).

    Returns
    -------
    float
        L, in units of the short semiaxis.
    """
    return max(4 * alpha / math.sqrt(1 + alpha**2), 2 * alpha)


def layer_spacing(alpha: float) -> float:
    """Smallest height z between crossed layers at which no spheroids overlap (root of zeta = 0).

    Parameters
    ----------
    alpha : float
        Aspect ratio of the spheroids.

    Returns
    -------
    float
        z, in units of the short semiaxis.
    """
    side = square_side(alpha)
    along_x = _inverse((alpha, 1.0, 1.0), _IDENTITY)  # layer B: long axis along x
    along_y = _inverse((alpha, 1.0, 1.0), _LONG_Y)  # layer A: long axis along y

    def worst(z):
        return min(_zeta((side / 2, 0.0, z), along_y, along_x), _zeta((0.0, side / 2, z), along_y, along_x))

    if worst(0.0) >= 0:  # only for alpha = 1 exactly can the layers not interpenetrate at z = 0
        return 0.0
    return brentq(worst, 0.0, 2.0, xtol=1e-15, rtol=4 * np.finfo(float).eps)


def laminate(alpha: float) -> Packing:
    """The laminate packing of spheroids with semiaxes 1 : alpha : 1 (module docstring), 4 per cell.

    Parameters
    ----------
    alpha : float
        In-plane aspect ratio, >= 1 (use 1 / alpha's packing with the long semiaxis in the layer
        for oblate shapes: phi(alpha) = phi(1 / alpha)).

    Returns
    -------
    Packing
        4 spheroids in an orthorhombic periodic cell L x L x 2z.

    Raises
    ------
    InvalidInputError
        If ``alpha`` is not a finite number >= 1.
    """
    if not (isinstance(alpha, (int, float)) and math.isfinite(alpha) and alpha >= 1):
        raise InvalidInputError(f"laminate: alpha must be a finite number >= 1, got {alpha!r}")
    side, z = square_side(alpha), layer_spacing(alpha)
    positions = np.array([[0, 0, 0], [side / 2, side / 2, 0], [side / 2, 0, z], [0, side / 2, z]], float)
    semiaxes = np.tile([alpha, 1.0, 1.0], (4, 1))
    orientations = np.array([_LONG_Y, _LONG_Y, _IDENTITY, _IDENTITY])
    lattice = np.diag([side, side, 2 * z])
    return Packing(positions, lattice=lattice, shape=Ellipsoids(semiaxes, orientations))


def stretched_alpha(s: float) -> float:
    """In-plane aspect ratio of the densest laminate stretched by ``s`` along (1, 1, 0) (Eq. 8.3).

    alpha^2 = [(2 + s^2 + 2 s^4) + 2 (1 + s^2) sqrt(1 - s^2 + s^4)] / (3 s^2).

    Parameters
    ----------
    s : float
        Stretch factor, s >= 1.

    Returns
    -------
    float
        alpha(s).
    """
    root = math.sqrt(1 - s**2 + s**4)
    return math.sqrt(((2 + s**2 + 2 * s**4) + 2 * (1 + s**2) * root) / (3 * s**2))


def _quaternion(rotation) -> np.ndarray:
    """(s, p) of the lab-to-body rotation Q (rows = body axes): Q = R(w)^T for the rotation R(w)
    of Donev 2006, Eq. 1.7 (:mod:`hardpack.geometry.shapes`)."""
    x, y, z, w = Rotation.from_matrix(np.asarray(rotation).T).as_quat()
    return np.array([w, x, y, z])


def stretched_laminate(s: float) -> Packing:
    """The densest laminate (alpha = sqrt(3)) stretched by ``s`` along (1, 1, 0) / sqrt(2).

    An affine map F keeps every contact and the density; each spheroid becomes the ellipsoid
    X'^-1 = F X^-1 F^T, a spheroid again, of in-plane aspect ratio :func:`stretched_alpha` (Donev
    2006, Sec. 8.2, Eq. 8.3, Fig. 8.3).

    Parameters
    ----------
    s : float
        Stretch factor, >= 1.

    Returns
    -------
    Packing
        4 ellipsoids in the sheared periodic cell F L (phi = 0.770732 for every s).

    Raises
    ------
    InvalidInputError
        If ``s`` is not a finite number >= 1.
    """
    if not (isinstance(s, (int, float)) and math.isfinite(s) and s >= 1):
        raise InvalidInputError(f"stretched_laminate: s must be a finite number >= 1, got {s!r}")
    base = laminate(DENSEST_ALPHA)
    e = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
    f = np.eye(3) + (s - 1) * np.outer(e, e)
    semiaxes, orientations = [], []
    for inv in base.shape.shape_matrices():
        values, vectors = np.linalg.eigh(f @ np.linalg.inv(inv) @ f.T)
        if np.linalg.det(vectors) < 0:
            vectors[:, 0] *= -1
        semiaxes.append(np.sqrt(values))
        orientations.append(_quaternion(vectors.T))
    return Packing(base.positions @ f.T, lattice=f @ base.lattice,
                   shape=Ellipsoids(np.array(semiaxes), np.array(orientations)))


def stretch_for(alpha: float) -> float:
    """The stretch s >= 1 of the densest laminate that gives in-plane aspect ratio ``alpha`` >= sqrt(3)
    (the inverse of :func:`stretched_alpha`, increasing in s).

    Parameters
    ----------
    alpha : float
        In-plane aspect ratio, >= sqrt(3).

    Returns
    -------
    float
        s.

    Raises
    ------
    InvalidInputError
        For alpha below sqrt(3) or not finite.
    """
    if not (math.isfinite(alpha) and alpha >= DENSEST_ALPHA):
        raise InvalidInputError(f"stretch_for: alpha must be a finite number >= sqrt(3), got {alpha!r}")
    if alpha == DENSEST_ALPHA:
        return 1.0
    upper = 2.0
    while stretched_alpha(upper) < alpha:
        upper *= 2
    return brentq(lambda s: stretched_alpha(s) - alpha, 1.0, upper, xtol=1e-14, rtol=4 * np.finfo(float).eps)


def _crystal_numbers(packing) -> tuple[float, float, float]:
    """(phi, contacts per particle, largest relative overlap 1 - mu) of a crystal packing."""
    from hardpack.geometry.ellipsoid_stats import ellipsoid_contacts

    contacts = ellipsoid_contacts(packing, tol=CRYSTAL_CONTACT_TOL, min_contacts=1)
    overlap = float(np.max(1 - contacts.contacts.mu)) if len(contacts.contacts.mu) else -np.inf
    return packing.phi, float(contacts.degree.mean()), overlap


def laminate_family(alphas) -> xr.Dataset:
    """The laminate crystals vs in-plane aspect ratio (Donev 2006, Sec. 8.2, Fig. 8.2).

    For every alpha >= 1: the unstretched laminate (:func:`laminate`; for alpha > sqrt(3) its
    neighbours along the long axis hold it, L = 2 alpha, and its density falls) and the densest
    known crystal of that shape ("presently maximal" curve of Fig. 8.2): the laminate up to
    sqrt(3), the densest laminate stretched by :func:`stretch_for` beyond (:func:`stretched_laminate`,
    phi = 0.770732 for every stretch). phi(1 / alpha) = phi(alpha): oblate shapes share the values.

    Parameters
    ----------
    alphas : sequence of float
        Aspect ratios, each finite and >= 1.

    Returns
    -------
    xarray.Dataset
        Dimension ``alpha``; variables ``phi_laminate``, ``phi_densest``, ``stretch`` (1 up to
        sqrt(3)), ``contacts_laminate`` and ``contacts_densest`` (contacts per particle within
        relative gap :data:`CRYSTAL_CONTACT_TOL`), ``overlap_laminate`` and ``overlap_densest``
        (largest 1 - mu over the contacts: round-off, never a real overlap).

    Raises
    ------
    InvalidInputError
        If an alpha is not a finite number >= 1, or ``alphas`` is empty.
    """
    alphas = np.asarray(alphas, dtype=float).ravel()
    if alphas.size == 0 or not np.all(np.isfinite(alphas)) or np.any(alphas < 1):
        raise InvalidInputError(f"laminate_family: alphas must be finite numbers >= 1, got {alphas.tolist()}")
    columns = {name: np.empty(alphas.size) for name in
               ("phi_laminate", "contacts_laminate", "overlap_laminate",
                "phi_densest", "contacts_densest", "overlap_densest", "stretch")}
    for k, alpha in enumerate(alphas):
        base = _crystal_numbers(laminate(float(alpha)))
        s = stretch_for(float(alpha)) if alpha > DENSEST_ALPHA else 1.0
        densest = _crystal_numbers(stretched_laminate(s)) if alpha > DENSEST_ALPHA else base
        for suffix, numbers in (("laminate", base), ("densest", densest)):
            for name, value in zip(("phi", "contacts", "overlap"), numbers):
                columns[f"{name}_{suffix}"][k] = value
        columns["stretch"][k] = s
    ds = xr.Dataset({name: ("alpha", values) for name, values in columns.items()}, coords={"alpha": alphas})
    ds.attrs.update(hardpack_kind="laminate_family", contact_tol=CRYSTAL_CONTACT_TOL,
                    densest_alpha=DENSEST_ALPHA, d=3)
    return ds
