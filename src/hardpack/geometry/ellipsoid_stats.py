"""Contacts, rattlers, contact number and nematic order of ellipsoid and ellipse packings.

Contacts (Donev 2006, Sec. 5.2): pairs whose Perram-Wertheim scale factor to tangency
mu = sqrt(zeta + 1) is within the gap tolerance, mu - 1 < tol (for spheres mu - 1 is the
relative gap distance / (r_i + r_j) - 1); Donev finds the contact number Z reasonably constant for
tol from 1e-9 to 1e-4. Every periodic image counts (a contact with the particle's own image counts
twice for it).

Rattlers: particles with fewer than d + 1 contacts are removed one pass after another until every
remaining particle (the backbone) has at least d + 1 contacts among the backbone (as Algorithm 13
does for spheres with this same count, Donev 2006, Sec. 4.4.1). The rule is d + 1, not
d_f + 1 with d_f = d(d + 1)/2 (or 5 for spheroids) degrees of freedom: with its orientation
frozen a particle moves like a sphere, and it can escape its neighbours unless their contact normals
positively span R^d, which needs d + 1 contacts, while its rotations can be blocked by the curvature
of fewer contacts (Donev 2006, Sec. 5.5.2: jammed packings of non-spherical particles need only
Z >= 2d, and are hypostatic, Z < 2 d_f, near the sphere point; Sec. 5.10). So d + 1 contacts are
necessary for a particle to be locally jammed, and d_f + 1 would remove jammed particles of
hypostatic packings. Donev's Sec. 5.2 counts as rattlers only particles without any contact; that
is ``min_contacts=1``.

Nematic order: the largest eigenvalue S of the order tensor of the particles' symmetry axes u_i,
Q = <(d u u^T - I) / (d - 1)>: in 3D Q = <(3 u u^T - I) / 2>, whose eigenvalue along the director
is <(3 cos^2 theta - 1) / 2>; in 2D Q = <2 u u^T - I>, with S = <cos 2 theta> about the director
(theta the angle of u with the director). S = 1 for perfect alignment and O(1/sqrt(N)) for
isotropic orientations (Donev 2006, Sec. 5.2 reports S ~ 0.02-0.05 for N = 1000 ellipsoids).
The symmetry axis of a particle is the body axis (:meth:`Ellipsoids.rotations`, rows) whose
semiaxis is farthest from the middle one in 3D (the unique axis of a spheroid: the long axis of a
prolate, the short one of an oblate; the longest on a tie) and the longest in 2D (the first of equal
longest semiaxes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.ellipsoid_pairs import PotentialPairs, potential_pairs

DEFAULT_CONTACT_TOL = 1e-9


@dataclass(frozen=True)
class EllipsoidContacts:
    """Contact network of an ellipsoid packing with its rattlers removed (module docstring).

    ``contacts``: the touching pairs (mu - 1 < ``tol``); ``degree``: contacts per particle;
    ``rattler``: the particles removed; ``backbone_degree``: contacts per particle among the
    backbone (0 for rattlers); ``passes``: removal passes until no particle had fewer than
    ``min_contacts``.

    Attributes
    ----------
    contacts : PotentialPairs
        The touching pairs.
    degree : numpy.ndarray of int, shape (N,)
        Contacts per particle.
    rattler : numpy.ndarray of bool, shape (N,)
        The particles removed.
    backbone_degree : numpy.ndarray of int, shape (N,)
        Contacts per particle among the backbone (0 for rattlers).
    passes : int
        Removal passes.
    tol : float
        Contact tolerance on mu - 1.
    min_contacts : int
        Fewest contacts a backbone particle has.
    """

    contacts: PotentialPairs
    degree: np.ndarray
    rattler: np.ndarray
    backbone_degree: np.ndarray
    passes: int
    tol: float
    min_contacts: int

    @property
    def n_rattlers(self) -> int:
        return int(self.rattler.sum())

    @property
    def mean_contact_number(self) -> float:
        """Z of the backbone: twice its contacts over its particles (nan if every particle rattles)."""
        n = int((~self.rattler).sum())
        return float(self.backbone_degree.sum() / n) if n else float("nan")

    def to_dataset(self) -> xr.Dataset:
        """The per-particle counts, the contact pairs and the summary numbers as a Dataset."""
        pairs = self.contacts.pairs
        return xr.Dataset(
            {"degree": ("particle", self.degree), "rattler": ("particle", self.rattler),
             "backbone_degree": ("particle", self.backbone_degree),
             "contact_i": ("contact", pairs.i), "contact_j": ("contact", pairs.j),
             "contact_shift": (("contact", "axis"), pairs.shift), "contact_mu": ("contact", self.contacts.mu)},
            attrs={"contact_tol": self.tol, "min_contacts": self.min_contacts, "removal_passes": self.passes,
                   "n_rattlers": self.n_rattlers, "mean_contact_number": self.mean_contact_number},
        )


def _require_periodic_ellipsoids(packing) -> None:
    if packing.shape.kind != "ellipsoid":
        raise InvalidInputError(f"this analysis is for ellipsoids and ellipses, got {packing.shape.name}")
    if packing.boundary.kind != "periodic":
        raise InvalidInputError(f"contacts with {packing.boundary.name} are not counted yet: this analysis "
                                f"handles periodic cells only (this packing has {packing.boundary})")


def _degrees(n, i, j, alive_pairs) -> np.ndarray:
    return np.bincount(i[alive_pairs], minlength=n) + np.bincount(j[alive_pairs], minlength=n)


def ellipsoid_contacts(packing, tol: float = DEFAULT_CONTACT_TOL, min_contacts: int | None = None) -> EllipsoidContacts:
    """Contacts of an ellipsoid packing and its backbone after iterative rattler removal.

    Parameters
    ----------
    packing : hardpack.geometry.Packing
        Ellipsoids or ellipses in a periodic cell.
    tol : float, default 1e-9
        Gap tolerance: a pair is in contact when mu - 1 < tol (module docstring), tol >= 0.
    min_contacts : int, optional
        Fewest contacts a backbone particle keeps; default d + 1 (module docstring). 1 gives
        Donev's Sec. 5.2 rattlers (particles without any contact).

    Returns
    -------
    EllipsoidContacts
        The contact pairs, degrees, rattlers and the backbone's contact number.

    Raises
    ------
    InvalidInputError
        If the packing is not of ellipsoids in a periodic cell, ``tol`` is negative or not finite,
        or ``min_contacts`` is not a positive integer.
    """
    _require_periodic_ellipsoids(packing)
    if not (np.isfinite(tol) and tol >= 0):
        raise InvalidInputError(f"the contact tolerance must be a finite number >= 0, got {tol}")
    d, n = packing.dim, packing.n_particles
    if min_contacts is None:
        min_contacts = d + 1
    if isinstance(min_contacts, bool) or not isinstance(min_contacts, (int, np.integer)) or min_contacts < 1:
        raise InvalidInputError(f"min_contacts must be a positive integer, got {min_contacts!r}")
    near = potential_pairs(packing, rel_gap=tol)
    contacts = near.subset(near.mu - 1.0 < tol)
    i, j = contacts.pairs.i, contacts.pairs.j
    degree = _degrees(n, i, j, np.ones(len(i), dtype=bool))
    alive = np.ones(n, dtype=bool)
    backbone_degree = degree.copy()
    passes = 0
    while True:
        weak = alive & (backbone_degree < min_contacts)
        if not weak.any():
            break
        passes += 1
        alive &= ~weak
        backbone_degree = np.where(alive, _degrees(n, i, j, alive[i] & alive[j]), 0)
    return EllipsoidContacts(contacts, degree, ~alive, backbone_degree, passes, float(tol), int(min_contacts))


def symmetry_axes(shape) -> np.ndarray:
    """Unit symmetry axis of every particle in the lab frame (module docstring), shape (N, d).

    Parameters
    ----------
    shape : hardpack.geometry.Ellipsoids
        The particles.

    Returns
    -------
    ndarray, shape (N, d)
        The body axis of each particle's symmetry axis, as a lab-frame unit vector (sign arbitrary).
    """
    axes = shape.semiaxes
    k = np.argmax(axes, axis=1)
    if shape.dim == 3:
        low, middle, high = np.sort(axes, axis=1).T
        k = np.where(high - middle >= middle - low, k, np.argmin(axes, axis=1))
    return shape.rotations()[np.arange(shape.n_particles), k, :]


def nematic_order(packing) -> tuple[float, np.ndarray]:
    """Nematic order parameter S and director of an ellipsoid packing (module docstring).

    Parameters
    ----------
    packing : hardpack.geometry.Packing
        Ellipsoids or ellipses (any boundary).

    Returns
    -------
    S : float
        Largest eigenvalue of Q = <(d u u^T - I) / (d - 1)>; 1 for perfect alignment.
    director : ndarray, shape (d,)
        Its unit eigenvector (sign arbitrary).

    Raises
    ------
    InvalidInputError
        If the packing does not hold ellipsoids or ellipses.
    """
    if packing.shape.kind != "ellipsoid":
        raise InvalidInputError(f"nematic order is defined here for ellipsoids and ellipses, got {packing.shape.name}")
    u = symmetry_axes(packing.shape)
    d = packing.dim
    q = (d * np.einsum("ni,nj->ij", u, u) / len(u) - np.eye(d)) / (d - 1)
    values, vectors = np.linalg.eigh(q)
    return float(values[-1]), vectors[:, -1]


@dataclass(frozen=True)
class NearSphereLaw:
    """Fit of the contact number near the sphere point (Donev 2006, Eq. 5.30).

    Attributes
    ----------
    z_alpha : float
        Z_alpha of Z = 2d + Z_alpha sqrt(alpha - 1).
    z_alpha_err : float
        Its standard error (NaN with one point).
    rms_sqrt : float
        RMS residual of the square-root law.
    rms_linear : float
        RMS residual of the best linear law Z = 2d + c (alpha - 1), for comparison.
    n : int
        Packings in the fit.
    """

    z_alpha: float        #: Z_alpha of Z = 2d + Z_alpha sqrt(alpha - 1)
    z_alpha_err: float    #: its standard error (NaN with one point)
    rms_sqrt: float       #: rms residual of the square-root law
    rms_linear: float     #: rms residual of the best linear law Z = 2d + c (alpha - 1), for comparison
    n: int                #: packings in the fit


def near_sphere_contact_law(alpha, z, dim: int, alpha_max: float = 1.3) -> NearSphereLaw:
    """Fit Z = 2d + Z_alpha sqrt(alpha - 1) (Donev 2006, Sec. 5.9.2, Eq. 5.30) to packings with
    1 < alpha <= alpha_max.

    Near the sphere point a jammed packing gains contacts over the 2d of spheres as the
    square root of the asphericity; the text gives the law but no value of Z_alpha. The fit is a
    least-squares line through the origin in sqrt(alpha - 1); the same fit in (alpha - 1) is
    reported beside it, so that the data can tell the two laws apart.

    Parameters
    ----------
    alpha, z : array_like
        Aspect ratio and mean backbone contact number of each packing (same length).
    dim : int
        2 or 3 (2d is the contact number of jammed disks or spheres).
    alpha_max : float, default 1.3
        Largest aspect ratio counted as near the sphere point.

    Returns
    -------
    NearSphereLaw
        NaN fields when no packing has 1 < alpha <= alpha_max.

    Raises
    ------
    InvalidInputError
        If the arrays differ in shape, hold NaN, or ``dim`` is not 2 or 3.
    """
    a = np.asarray(alpha, float)
    zz = np.asarray(z, float)
    if a.shape != zz.shape or a.ndim != 1:
        raise InvalidInputError(f"alpha and z must be 1-d arrays of one length, got {a.shape} and {zz.shape}")
    if not (np.isfinite(a).all() and np.isfinite(zz).all()):
        raise InvalidInputError("alpha and z must be finite (a packing without a contact number cannot be fitted)")
    if dim not in (2, 3):
        raise InvalidInputError(f"dim must be 2 or 3, got {dim!r}")
    use = (a > 1.0) & (a <= alpha_max)
    if not use.any():
        return NearSphereLaw(*(float("nan"),) * 4, 0)
    y = zz[use] - 2 * dim

    def through_origin(x):
        c = float(x @ y / (x @ x))
        resid = y - c * x
        err = float(np.sqrt(resid @ resid / (len(y) - 1) / (x @ x))) if len(y) > 1 else float("nan")
        return c, err, float(np.sqrt(np.mean(resid**2)))

    c_sqrt, err, rms_sqrt = through_origin(np.sqrt(a[use] - 1.0))
    _, _, rms_linear = through_origin(a[use] - 1.0)
    return NearSphereLaw(c_sqrt, err, rms_sqrt, rms_linear, int(use.sum()))
