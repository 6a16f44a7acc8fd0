"""One ellipsoid (3D) or ellipse (2D) MD system in numba arrays, run window by window.

The window logic (neighbour-list persistence, spatial sorts, capacity doubling and redo of a
window after an overflow, bounding-radius caps, grid levels) is the sphere engine's
(:class:`hardpack.md.engine.Engine`), which this class extends: the bounding radius of a particle
(its largest semiaxis) plays the sphere radius there, so ``radii`` are bounding radii. The kernels
are :mod:`hardpack.md._ellipsoid_kernel`.
"""

from __future__ import annotations

import numpy as np

from hardpack.md import _ellipsoid_kernel as ek
from hardpack.md._kernel import WindowStatus
from hardpack.md.engine import Engine, WindowResult, _aligned_rows, wall_arrays


class EngineStalledError(RuntimeError):
    """The event loop stopped advancing the time (an engine failure, never valid input's fault)."""


def moments_of_inertia(semiaxes: np.ndarray) -> np.ndarray:
    """Spherically symmetric moment of inertia of unit-mass ellipsoids (N, 3) or ellipses (N, 2):
    (2/15)(a^2 + b^2 + c^2), the mean principal moment (exact for spheres), or (a^2 + b^2)/4
    (module docstring of :mod:`hardpack.md._ellipsoid_kernel`).

    Parameters
    ----------
    semiaxes : numpy.ndarray of float, shape (N, d), d = 2 or 3
        Semiaxes of each particle.

    Returns
    -------
    numpy.ndarray of float, shape (N,)
        Moment of inertia I of each particle (mass 1).
    """
    sq = np.einsum("ij,ij->i", semiaxes, semiaxes)
    return sq / 4.0 if semiaxes.shape[1] == 2 else 2.0 * sq / 15.0


def rotational_dof(d: int) -> int:
    """Rotational degrees of freedom of one particle: 1 in 2D, 3 in 3D.

    Parameters
    ----------
    d : int
        Dimension, 2 or 3.

    Returns
    -------
    int
        1 in 2D, 3 in 3D.
    """
    return 1 if d == 2 else 3


class EllipsoidEngine(Engine):
    """Numba state of N ellipsoids or ellipses in an orthorhombic periodic box, between hard flat
    walls at x_k = 0 and x_k = L_k (``boundary``, a :class:`hardpack.geometry.boundaries.HardWalls`)
    or in a spherical container (a :class:`hardpack.geometry.boundaries.SphericalContainer` inside
    the box, which then only serves the cell grid).

    Parameters
    ----------
    positions, velocities : numpy.ndarray of float, shape (N, d)
        Centres (inside the box) and velocities (unit masses).
    semiaxes : numpy.ndarray of float, shape (N, d)
        Semiaxes at window time 0.
    orientations : numpy.ndarray of float, shape (N, 4) in 3D, (N,) in 2D
        Unit quaternions (s, p_1, p_2, p_3), or angles of the first semiaxis with the x axis.
    angular_velocities : numpy.ndarray of float, shape (N, 3) in 3D, (N,) in 2D
        Lab-frame angular velocities.
    box : numpy.ndarray of float, shape (d,)
        Box side lengths.
    capacity : int, optional
        Initial neighbour-list capacity (doubled on overflow).
    eps_f : float, optional
        Trace tolerance (:data:`hardpack.md._ellipsoid_kernel.EPS_F`).
    boundary : HardWalls, SphericalContainer or None, optional
        Hard flat walls or a spherical container inside the box; None = periodic.
    """

    def __init__(self, positions, velocities, semiaxes, orientations, angular_velocities, box,
                 capacity: int = 32, eps_f: float = ek.EPS_F, boundary=None):
        n, d = positions.shape
        self.n, self.d = n, d
        self.eps_f = float(eps_f)
        self.box = np.ascontiguousarray(box, dtype=float)
        kind = "periodic" if boundary is None else boundary.kind
        if kind not in ("periodic", "hard_walls", "spherical_container"):
            raise ValueError(f"the ellipsoid engine runs periodic cells, hard walls or spherical containers, "
                             f"not {kind}")
        # the sphere kernel's walled axes and container, its mode as the ellipsoid kernel's run-time
        # code; the flat walls' positions added (hardpack.md._ellipsoid_kernel.run_events)
        mode, self.walled, self.wspec = wall_arrays(boundary, d)
        self.wmode = len(mode)
        if kind == "hard_walls":
            axes = list(boundary.axes)
            self.wspec[axes] = self.box[axes]
            self.wspec[d] = self.box[axes].max()
        cv, ct, cr, cax, cor, cw, cii, width = ek.columns(d)
        self.P = _aligned_rows(n, width)
        self.P[:, :d] = positions
        self.P[:, cv:cv + d] = velocities
        self.P[:, cr] = semiaxes.max(axis=1)
        self.P[:, cax:cax + d] = semiaxes
        self.P[:, cor:cw] = np.asarray(orientations, dtype=float).reshape(n, -1)
        self.P[:, cw:cii] = np.asarray(angular_velocities, dtype=float).reshape(n, -1)
        self.P[:, cii] = 1.0 / moments_of_inertia(semiaxes)
        self.cols = (cv, ct, cr, cax, cor, cw, cii)
        self.dims = tuple(range(d))
        from hardpack.md.engine import image_vectors

        self.imgvec = image_vectors(self.box)
        self.init_event_state(capacity)
        #: particles whose last event was at the end of the last window, and the relative growth
        #: rate there (what :meth:`rescale_velocities` checks)
        self.ended = np.zeros(0, dtype=np.int64)
        self.end_kappa = 0.0
        #: rescalings so far with two factors, with one factor, and left out
        #: (:meth:`rescale_velocities`)
        self.rescalings = np.zeros(3, dtype=np.int64)

    # ----------------------------------------------------------------- views of the state
    @property
    def velocities(self) -> np.ndarray:
        return self.P[:, self.cols[0]: self.cols[0] + self.d]

    @property
    def radii(self) -> np.ndarray:
        """Bounding radii (largest semiaxes): what the neighbour grid and lists use."""
        return self.P[:, self.cols[2]]

    @property
    def semiaxes(self) -> np.ndarray:
        return self.P[:, self.cols[3]: self.cols[3] + self.d]

    @property
    def orientations(self) -> np.ndarray:
        o = self.P[:, self.cols[4]: self.cols[5]]
        return o[:, 0] if self.d == 2 else o

    @property
    def angular_velocities(self) -> np.ndarray:
        w = self.P[:, self.cols[5]: self.cols[6]]
        return w[:, 0] if self.d == 2 else w

    @property
    def inertia(self) -> np.ndarray:
        return 1.0 / self.P[:, self.cols[6]]

    def totals(self) -> tuple[float, float, float]:
        """(translational kinetic energy, sum of volume-equivalent radii (prod a)^(1/d), sum of
        prod a), summed in a fixed order: the sphere engine's triple, so that phi and the growth
        rate convention (mean volume-equivalent radius) carry over."""
        ket, _, s1, sd = ek.totals(self.P)
        return float(ket), float(s1), float(sd)

    def energies(self) -> tuple[float, float]:
        """(translational, rotational) kinetic energy."""
        ket, ker, _, _ = ek.totals(self.P)
        return float(ket), float(ker)

    def momentum(self) -> np.ndarray:
        """Total translational momentum sum_i v_i (unit masses).

        Returns
        -------
        numpy.ndarray of float, shape (d,)
            The momentum.
        """
        return self.velocities.sum(axis=0)

    def kinetic_temperature(self) -> float:
        """kT = 2 (KE_trans + KE_rot) / ((d + d_rot) N)."""
        return 2.0 * sum(self.energies()) / ((self.d + rotational_dof(self.d)) * self.n)

    # ----------------------------------------------------------------- one window
    # (the window loop is Engine.run_window; ``log``, collision logging for contact forces, is not
    # implemented for ellipsoids. ``checks`` (CHECK events) and contact-function evaluations of
    # the last window are stored in :attr:`last_checks` and :attr:`last_evaluations`.)
    def _run_events(self, kappa, eff_skin, coll_target, cap, rebuild, log):
        if log is not None:
            raise NotImplementedError("collision logging (contact forces) is not implemented for ellipsoids")
        acc = np.zeros(ek.N_ACC)
        acc[3] = self.totals()[0]
        iacc = np.zeros(ek.N_COUNTERS, dtype=np.int64)
        status = WindowStatus(ek.run_events(
            self.P, self.box, kappa, self.eps_f, eff_skin, self.sfac, self.imgvec, self.lvl,
            self.rcap, self.ncl, self.coff, self.ccount, self.cid, self.cbs, self.slot_of,
            self.bs, self.nb, self.nn, self.mark, self.cnt, self.ep, self.ec, self.hkey,
            self.heap, self.hpos, acc, iacc, coll_target, cap, rebuild, self.wmode, self.wspec))
        return status, acc, iacc

    def _raise_stalled(self, acc, iacc):
        t, i, p = float(acc[0]), int(iacc[ek.I_STALL_PARTICLE]), int(iacc[ek.I_STALL_PARTNER])
        what = {ek.EXIT: "a neighbour-list exit", ek.CHECK: "a trace CHECK"}.get(p, f"particle {p}")
        if p <= ek.WALL:
            w = ek.WALL - p
            what = ("the container wall" if self.wmode == ek.SPHERE_CODE
                    else f"the wall x_{w >> 1} = {'L' if w & 1 else '0'}")
        raise EngineStalledError(
            f"the ellipsoid event loop stalled at window time {t!r}: more than "
            f"{ek.STALL_EVENTS + 10 * self.n} consecutive events at that time without a "
            f"collision (the last one of "
            f"particle {i} with {what}, engine order); the state is back at the window start. "
            "This is an engine failure: report it with the start packing, seed and options")

    def _window_result(self, acc, iacc, kappa):
        duration = float(acc[0])
        self.last_duration = duration
        self.ended = np.flatnonzero(self.P[:, self.cols[1]] == duration).astype(np.int64)
        self.end_kappa = kappa / (1.0 + kappa * duration)
        ek.synchronise(self.P, duration, kappa)
        worst, n_over = ek.max_overlap(self.P, self.imgvec, self.nb, self.nn)
        self.last_checks = int(iacc[ek.I_CHECK])
        self.last_evaluations = int(acc[ek.A_EVAL])
        return WindowResult(
            duration=duration, virial=float(acc[1]), ke_integral=float(acc[2]),
            ke_end=self.totals()[0], collisions=int(iacc[0]), events=int(iacc[1]),
            stale=int(iacc[2]), exits=int(iacc[3]), grazing=int(iacc[4]),
            max_overlap=float(worst), n_overlapping=int(n_over), mean_neighbours=float(self.nn.mean()),
            wall_collisions=int(iacc[ek.I_WALL]),
            wall_momentum=acc[ek.A_WALL:ek.A_WALL + self.d].copy(),
        )

    def rescale_velocities(self, kt: float = 1.0) -> None:
        """The thermostat of LS growth (Donev 2006, sec. 3.2.4.1): translational and rotational
        temperatures, kT_trans = 2 KE_trans / (d N) and kT_rot = 2 KE_rot / (d_rot N), each set
        to ``kt``. All velocities are scaled by the one factor s_t that sets kT_trans; the
        angular velocities of the particles whose last event was at the window end (the partners
        of its last collision) and of their partners in contacts at the window end (below) by
        s_t as well, those of the others by the factor s_r' that then sets kT_rot. When s_r' does
        not exist (the former alone hold more than the target rotational energy after scaling,
        or no other particle rotates) all angular velocities are scaled by s_t; when even that
        would make a contact at the window end approach, nothing is scaled. :attr:`rescalings`
        counts the three cases (both temperatures set, kT_rot not set, left out). Rotations at
        rest stay at rest.

        *Why two temperatures.* One factor for translation and rotation keeps their split, which
        is right only while the collisions keep equipartition. Near the sphere point they hardly
        exchange energy with the rotations, and LS growth heats the translations only: with one
        factor s for all (kT_trans + kT_rot d_rot / d = (1 + d_rot / d) ``kt``), 16 spheres as
        ellipsoids (alpha = 1) after 100 windows at Gamma = 0.1 had kT_trans = 2.0 and kT_rot =
        2e-13 after the rescaling, so the growth was up to sqrt(2) slower than nominal in units
        of the thermal speed.

        *Why not two global factors (s_t, s_r).* The normal separation speed of a contact (the
        collision law of :mod:`hardpack.md._ellipsoid_kernel`, < 0 approaching) is linear in the
        velocities: v_n = s_t A + s_r B + G after the scaling, with A = n . (v_B - v_A) its
        translational part, B = n . (w_B x r_B - w_A x r_A) its rotational part and
        G = -g r_AB . n <= 0 that of the growth (g the relative growth rate at the window end,
        which is the next window's kappa at the same Gamma: kappa' = Gamma / (2 <a(T)>) =
        kappa / (1 + kappa T)); a wall contact likewise with the particle's own terms. The window
        ends at its last collision, whose pair (or particle and wall) is exactly at contact,
        separating at u = A + B + G > 0 (the law reverses the approach). For s_t != s_r,
        s_t A + s_r B + G takes any sign and size when A and B have opposite signs: it turns the
        direction of the contact's velocities every window. With a budget of one collision per
        window (one ellipsoid in a container, Gamma = 0.1) this map of collision and rescaling
        drove the particle to graze the wall: after 370 windows it left the wall at 1e-9 thermal
        speeds, windows lasted 2e-9 and phi stayed at 0.032 for more than 20000 windows (a check
        of the sign alone does not prevent this: the speed stays positive).
        Scaling all velocities of the contact's particles by one factor s_t keeps their
        direction (as the one-factor thermostat does): v_n = s_t u + (1 - s_t) G, the
        collision's own separation shrunk with the energy, which is negative only when s_t < 1
        and u < (1 - s_t) |G| / s_t (a collision at the resolution of the growth speed). The
        contacts at the window end (:func:`hardpack.md._ellipsoid_kernel.end_contacts`: the
        pairs within zeta <= END_CONTACT_GAP and the wall contacts of those particles; every
        particle after a window of zero length) are therefore checked
        (:func:`hardpack.md._ellipsoid_kernel.contact_rates`), and the window is left unscaled
        when one that did not approach would. The velocities that change direction belong to
        particles at a positive gap, whose collisions happen at a positive time of the next
        window. kT_trans = kT_rot = ``kt`` needs only that the particles of the last collision
        hold less than the target rotational energy: measured, both were set at every window of
        a compression of 16 spheres or 1.05-spheroids (Gamma = 0.1; ``tests/test_ellipsoid_md.py``).

        Parameters
        ----------
        kt : float
            Target temperature.
        """
        cv, _, _, _, _, cw, cii = self.cols
        d, n, P = self.d, self.n, self.P
        contacts = np.zeros((0, 3), dtype=np.int64)
        if self.ended.size and self.lists_valid:
            contacts = ek.end_contacts(P, self.ended, self.imgvec, self.nb, self.nn, self.wmode, self.wspec)
        at_end = np.zeros(n, dtype=bool)  # the particles scaled by one factor
        if self.lists_valid:
            at_end[self.ended] = True
            at_end[contacts[contacts[:, 1] >= 0, 1]] = True
        ket, _ = self.energies()
        st = np.sqrt(0.5 * kt * d * n / ket) if ket > 0.0 else 1.0
        ke_rot = 0.5 * np.einsum("ij,ij->i", P[:, cw:cii], P[:, cw:cii]) / P[:, cii]
        ker_end = float(ke_rot[at_end].sum())
        ker_rest = float(ke_rot[~at_end].sum())
        target = 0.5 * kt * rotational_dof(d) * n
        rot = np.full(n, st)
        choice = 1
        if ker_rest > 0.0 and st * st * ker_end < target:
            rot[~at_end] = np.sqrt((target - st * st * ker_end) / ker_rest)
            choice = 0
        if len(contacts):
            before = ek.contact_rates(P, contacts, self.imgvec, self.end_kappa, self.wmode, self.wspec) >= 0.0
            trial = P.copy()
            trial[:, cv:cv + d] *= st
            trial[:, cw:cii] *= rot[:, None]
            after = ek.contact_rates(trial, contacts, self.imgvec, self.end_kappa, self.wmode, self.wspec)
            if np.any(before & (after < 0.0)):
                st, rot, choice = 1.0, np.ones(n), 2
        self.rescalings[choice] += 1
        P[:, cv:cv + d] *= st
        P[:, cw:cii] *= rot[:, None]
