"""MD contact forces: per-pair collision impulses summed over the final synchronisation windows.

Near jamming every particle rattles in a cage of near-contacts, and the time-averaged momentum
exchanged per pair is the contact force of the packing up to a common factor (Donev 2006,
sec. 1.1 and Fig. 1.1; Algorithm 12 step 7). Over windows of total duration tau with
kinetic temperatures kT(t) (m = 1), the pair (i, j) collides many times with impulses J on j (from
i, along the contact normal); we store, in units with kT = 1,

    F_ij = sum J / int kT dt            (time-averaged force exerted by i on j, a d-vector)
    W_ij = sum r_ij . J / int kT dt     (its time-averaged virial, r_ij = x_j - x_i at each collision)

with int kT dt = 2 int KE dt / (d N). The collision virial gives the window pressure
(derived here from the collisional stress of Donev 2006, sec. 3.2.4.2)

    Z = p V / (N <kT>) = 1 + sum_pairs W_ij / (d N),    i.e.   p V / <kT> = N + sum_pairs W_ij / d,

exactly (the same terms summed in another order), and F_ij . r_ij with r_ij from the final packing
equals W_ij up to the relative change of r_ij over the windows, about the relative gap d / Z.

Pairs are reported once, i < j in the caller's particle order, with the integer lattice shift n
such that r_ij = x_j + L n - x_i is the contact vector in the final (wrapped) packing.
"""

from __future__ import annotations

from collections import deque

import numpy as np
import xarray as xr

from hardpack.geometry.packing import Packing


def _reduce(key: np.ndarray, vals: np.ndarray, count: np.ndarray):
    """Sum rows of ``vals`` and ``count`` with equal ``key`` (sorted unique keys, fixed order)."""
    uniq, inv = np.unique(key, return_inverse=True)
    sums = np.stack([np.bincount(inv, weights=vals[:, k], minlength=len(uniq))
                     for k in range(vals.shape[1])], axis=1)
    return uniq, sums, np.bincount(inv, weights=count, minlength=len(uniq)).astype(np.int64)


class ContactAccumulator:
    """Impulse sums of the last ``windows`` windows, one table per window (module docstring).

    Parameters
    ----------
    n : int
        Number of particles.
    d : int
        Dimension.
    windows : int
        Number of most recent windows kept.
    """

    def __init__(self, n: int, d: int, windows: int):
        self.n, self.d, self.windows = n, d, int(windows)
        self.tables: deque = deque()  # (keys, sums (m, d + 1), counts, ke_integral, duration)

    def add(self, pairs: np.ndarray, values: np.ndarray, duration: float, ke_integral: float) -> None:
        """Add one window's collisions; keeps the last ``windows`` windows.

        Parameters
        ----------
        pairs : numpy.ndarray of int, shape (M, 2)
            The colliding pairs, in the caller's particle order.
        values : numpy.ndarray of float, shape (M, d + 1)
            Per collision, the impulse J on particle ``pairs[:, 1]`` (d entries) and r . J.
        duration : float
            MD time of the window.
        ke_integral : float
            Time integral of the total kinetic energy over the window.
        """
        i, j = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
        sign = np.where(i < j, 1.0, -1.0)
        vals = values.copy()
        vals[:, : self.d] *= sign[:, None]  # the impulse on the larger index, from the smaller
        key = np.minimum(i, j) * self.n + np.maximum(i, j)
        keys, sums, counts = _reduce(key, vals, np.ones(len(key)))
        self.tables.append((keys, sums, counts, float(ke_integral), float(duration)))
        while len(self.tables) > self.windows:
            self.tables.popleft()

    # ----------------------------------------------------------------- checkpoint state
    def state(self) -> dict:
        """The kept windows as flat arrays, for a checkpoint (:meth:`restore`).

        Returns
        -------
        dict of numpy.ndarray
            ``cf_window``, ``cf_key``, ``cf_sum`` (rows of d + 1), ``cf_count`` per pair and window,
            and ``cf_ke_integral`` and ``cf_duration`` per window.
        """
        t = list(self.tables)
        width = self.d + 1
        return {
            "cf_window": np.concatenate([np.full(len(k), w) for w, (k, *_) in enumerate(t)] or [np.zeros(0)]),
            "cf_key": np.concatenate([k for k, *_ in t] or [np.zeros(0, np.int64)]),
            "cf_sum": np.concatenate([s for _, s, *_ in t] or [np.zeros((0, width))]),
            "cf_count": np.concatenate([c for _, _, c, *_ in t] or [np.zeros(0, np.int64)]),
            "cf_ke_integral": np.array([x[3] for x in t]), "cf_duration": np.array([x[4] for x in t]),
        }

    def restore(self, state: dict) -> None:
        """Load a :meth:`state`, replacing the windows kept.

        Parameters
        ----------
        state : dict
            The arrays of :meth:`state` (e.g. read back from a checkpoint).
        """
        win = np.asarray(state["cf_window"]).reshape(-1)
        key = np.asarray(state["cf_key"], dtype=np.int64).reshape(-1)
        sums = np.asarray(state["cf_sum"], dtype=float).reshape(-1, self.d + 1)
        count = np.asarray(state["cf_count"], dtype=np.int64).reshape(-1)
        keint = np.atleast_1d(np.asarray(state["cf_ke_integral"], dtype=float))
        dur = np.atleast_1d(np.asarray(state["cf_duration"], dtype=float))
        self.tables = deque(
            (key[win == w], sums[win == w], count[win == w], float(keint[w]), float(dur[w]))
            for w in range(len(dur))
        )

    # ----------------------------------------------------------------- result
    def result(self, packing: Packing) -> xr.Dataset:
        """The contact forces of the accumulated windows for the final ``packing`` (module docstring).

        Parameters
        ----------
        packing : Packing
            The final packing, in the particle order of :meth:`add`; the shifts n are taken from
            the diagonal of its lattice (an orthorhombic cell).

        Returns
        -------
        xarray.Dataset
            Variables md_contact_{i, j, collisions} on dimension ``md_contact`` and md_contact_{shift,
            force} on (``md_contact``, ``dim``), md_contact_virial; attributes md_contact_windows,
            md_contact_duration, md_contact_kT_mean, md_contact_Z and md_contact_total_collisions.
            Forces, virials and Z are NaN when no kinetic energy was accumulated.
        """
        n, d = self.n, self.d
        t = list(self.tables)
        if t:
            keys, sums, counts = _reduce(np.concatenate([x[0] for x in t]),
                                         np.concatenate([x[1] for x in t]),
                                         np.concatenate([x[2] for x in t]))
        else:
            keys, sums, counts = np.zeros(0, np.int64), np.zeros((0, d + 1)), np.zeros(0, np.int64)
        keint = sum(x[3] for x in t)
        duration = sum(x[4] for x in t)
        kt_time = 2.0 * keint / (d * n)  # integral of kT dt
        i, j = keys // n, keys % n
        box = np.diag(packing.lattice)
        x = packing.positions
        shift = -np.rint((x[j] - x[i]) / box).astype(np.int64)
        scale = 1.0 / kt_time if kt_time > 0 else np.nan
        virial = sums[:, d] * scale
        z = 1.0 + virial.sum() / (d * n) if kt_time > 0 else np.nan
        attrs = {
            "md_contact_windows": len(t), "md_contact_duration": duration,
            "md_contact_kT_mean": kt_time / duration if duration > 0 else np.nan,
            "md_contact_Z": float(z), "md_contact_total_collisions": int(counts.sum()),
        }
        ds = xr.Dataset(
            {
                "md_contact_i": ("md_contact", i, {"description": "first particle (i < j)"}),
                "md_contact_j": ("md_contact", j, {"description": "second particle"}),
                "md_contact_shift": (("md_contact", "dim"), shift, {
                    "description": "lattice shift n: r_ij = x_j + L n - x_i in the final packing"}),
                "md_contact_force": (("md_contact", "dim"), sums[:, :d] * scale, {
                    "description": "time-averaged force on j from i, sum of impulses / int kT dt "
                                   "(m = kT = 1)"}),
                "md_contact_virial": ("md_contact", virial, {
                    "description": "time-averaged r_ij . F_ij over the collisions (kT = 1); "
                                   "Z = 1 + sum / (d N)"}),
                "md_contact_collisions": ("md_contact", counts, {
                    "description": "collisions of the pair in the windows"}),
            },
            attrs=attrs,
        )
        return ds
