"""Exact LP solutions through the self-stress space of a rigid, nearly isostatic backbone.

Generic disordered packings from LS / MD have, after rattler removal, a backbone that is rigid
(rank A' = N_f = d(N_b - 1); A' is A without one "anchor" particle's rows, which fixes the
translation; with walls A' drops the coordinates of
:func:`hardpack.jamming.rigidity.gauge_dofs`) with M = N_f + K contacts, K small (K = 1:
isostatic, Donev 2006, Eq. 4.8; a few more with near contacts inside delta). Then every LP
the tests need reduces, through one sparse LU factorisation, to an LP in K unknowns. Derivations (ours):

- Self-stress space. Remove K columns R from A' so that the square A'_{-R} is regular (LU).
  For each removed column c, n_c = e_c - A'_{-R}^{-1} a'_c (on the kept columns) solves
  A' n_c = 0: the K columns n_c span null(A'). A strictly positive self-stress exists iff
  max t s.t. N alpha >= t, sum(N alpha) = M has t > 0; otherwise the LP polytope is unbounded
  (Stiemke) and the callers use HiGHS, which finds the unjamming motion.
- Load B (collective test, LP 4.10 and its dual 4.12 without the box): the dual is
  min h^T f s.t. A' f = -B, f >= 0. With y a particular solution (y_R = 0, LU solve), f = y + N
  alpha, a K-variable LP solved by HiGHS in milliseconds (closed form for K = 1: the contact
  with the smallest y_j / f0_j opens). At its (nondegenerate) optimum exactly N_f forces are
  positive; complementary slackness closes those contacts and leaves K slacks sigma_Q unknown,
  fixed by the K rows the LU left out: K + 1 triangular solves with the same LU and a K x K
  system give the displacement, the same vertex a simplex method returns. If the vertex is
  degenerate or leaves the LP box, the callers fall back to HiGHS.
- Strain (strict test): the strain adds d(d+1)/2 unknowns and one constraint (trace), so for
  K <= d(d+1)/2 - 2 the strict LP is unbounded. An exact unjamming direction is a strain with
  Tr eps = 0 and S_c . eps = 0 for the stress S_c = A_eps n_c of every self-stress (Eq. 4.23):
  then A'^T dR = -A_eps^T eps is consistent, and (dR, eps) keeps every contact closed to first
  order at constant volume. We project the random strain load onto that subspace and scale it
  to the LP box.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from hardpack.jamming.contacts import ContactNetwork
from hardpack.jamming.lp import LPFailure, solve_lp
from hardpack.jamming.rigidity import (
    anchored_transpose,
    strain_coefficients,
    strain_pairs,
    strain_tensor,
)
from hardpack.jamming.workingset import structurally_regular

#: backbones with more than this many self-stresses are left to HiGHS
MAX_SELF_STRESSES = 12


@dataclass
class RigidBackbone:
    """LU factorisation and self-stress basis of a rigid backbone (module docstring).

    Attributes
    ----------
    free : numpy.ndarray of bool, shape (N d,)
        Coordinates with variables (backbone less the gauge, :func:`hardpack.jamming.rigidity.gauge_dofs`).
    contacts : numpy.ndarray of bool, shape (M,)
        The backbone contacts.
    a : scipy.sparse.csc_matrix, shape (N_f, M_b)
        A' restricted to the free coordinates and backbone contacts.
    lu : scipy.sparse.linalg.SuperLU
        LU factorisation of A' without the columns ``removed``.
    removed : numpy.ndarray of int, shape (K,)
        The K removed column indices R.
    null : numpy.ndarray of float, shape (M_b, K)
        Basis of the self-stresses.
    f0 : numpy.ndarray of float, shape (M_b,)
        Most uniform strictly positive self-stress, mean 1.
    h : numpy.ndarray of float, shape (M_b,)
        Contact gaps.
    """

    free: np.ndarray  # (N d,) coordinates with variables (backbone less the gauge, rigidity.gauge_dofs)
    contacts: np.ndarray  # (N_contacts,) mask of the backbone contacts
    a: object  # A' (csc), (N_f, M)
    lu: object  # splu of A'_{-R}
    removed: np.ndarray  # R, K column indices
    null: np.ndarray  # (M, K) basis of the self-stresses
    f0: np.ndarray  # (M,) most uniform strictly positive self-stress, mean 1
    h: np.ndarray  # (M,) gaps

    @classmethod
    def build(cls, net: ContactNetwork, backbone: np.ndarray) -> RigidBackbone | None:
        """Factorise the backbone ``backbone`` of ``net`` and find its self-stresses (module docstring).

        Parameters
        ----------
        net : ContactNetwork
            The contact network of the packing.
        backbone : numpy.ndarray of bool, shape (N,)
            The backbone particles; its contacts are those of ``net`` among them.

        Returns
        -------
        RigidBackbone or None
            None (the callers use HiGHS) unless the backbone is rigid with 1 <= K <= MAX_SELF_STRESSES
            self-stresses (K = M_b - N_f), a regular square subsystem is found (four random choices
            of the removed columns), the self-stress basis is accurate, and a strictly positive
            self-stress exists; also None for a container backbone on which not every rotation acts.
        """
        d = net.dim
        contacts = net.among(backbone)
        m, nb = int(contacts.sum()), int(backbone.sum())
        nf = d * nb - net.n_trivial if nb else 0  # with the gauge of rigidity.gauge_dofs
        k = m - nf
        if nf <= 0 or not 1 <= k <= MAX_SELF_STRESSES:
            return None
        free, at = anchored_transpose(net, backbone, contacts)
        if at.shape[1] != nf:  # a container backbone on which not every rotation acts
            return None
        a = at.T.tocsc()
        rng = np.random.default_rng(0)
        norms = np.asarray(abs(a).sum(axis=0)).ravel()
        for attempt in range(4):  # a regular square subsystem: keep all but K columns
            removed = np.argsort(-norms)[:1] if attempt == 0 else np.array([], dtype=int)
            others = np.setdiff1d(np.arange(m), removed)
            removed = np.sort(np.r_[removed, rng.choice(others, k - removed.size, replace=False)])
            rest = np.setdiff1d(np.arange(m), removed)
            lu = None
            square = a[:, rest].tocsc()
            if not structurally_regular(square):  # SuperLU must not see it (_factorise)
                continue
            try:
                lu = spla.splu(square, permc_spec="COLAMD")
                break
            except RuntimeError:  # exactly singular
                lu = None
        if lu is None:
            return None
        null = np.zeros((m, k))
        null[removed, np.arange(k)] = 1.0
        null[rest] = lu.solve(-a[:, removed].toarray())
        if not np.all(np.isfinite(null)) or np.abs(a @ null).max() > 1e-9 * np.abs(null).max():
            return None
        f0 = _uniform_self_stress(null)
        if f0 is None:
            return None
        return cls(free, contacts, a, lu, removed, null, f0, net.gap[contacts])

    @property
    def n_self_stresses(self) -> int:
        return self.null.shape[1]

    def optimum(self, load: np.ndarray, d: int, box: float) -> tuple[np.ndarray, np.ndarray] | None:
        """Optimal vertex of LP (4.10) of Donev 2006 for ``load``, through the self-stress space.

        Parameters
        ----------
        load : numpy.ndarray of float, shape (N, d)
            The load B on every particle (only the free coordinates are used).
        d : int
            Dimension.
        box : float
            Bound on every displacement component; a vertex beyond it is refused.

        Returns
        -------
        tuple of (numpy.ndarray, numpy.ndarray) or None
            (displacement (N, d), zero on the coordinates without variables; forces (M_b,) on the
            backbone contacts, >= 0), or None when the LP in the self-stress coordinates fails, the
            vertex is degenerate or leaves the box, or the slacks of the open contacts come out
            singular or negative (use HiGHS then).
        """
        m = self.f0.size
        y = np.zeros(m)
        rest = np.setdiff1d(np.arange(m), self.removed)
        y[rest] = self.lu.solve(-np.asarray(load, dtype=float).reshape(-1)[self.free])
        if self.n_self_stresses == 1:  # closed form: the contact with the smallest y / f0 opens
            n0 = self.null[:, 0] if self.null[:, 0].sum() > 0 else -self.null[:, 0]
            ratio = y / n0
            forces = y - ratio.min() * n0
        else:
            try:
                res = solve_lp(self.h @ self.null, A_ub=-self.null, b_ub=y,
                               bounds=[(None, None)] * self.n_self_stresses)
            except LPFailure:
                return None
            forces = y + self.null @ res.x
        support = forces > 1e-12 * np.abs(forces).max()
        if support.sum() != self.a.shape[0]:
            return None
        x = self._closed_vertex(np.flatnonzero(~support), rest)
        if x is None:
            return None
        if np.abs(x).max() > box:
            return None
        disp = np.zeros(self.free.size)
        disp[self.free] = x
        disp = disp.reshape(-1, d)
        return disp, np.maximum(forces, 0.0)

    def _closed_vertex(self, open_set: np.ndarray, rest: np.ndarray) -> np.ndarray | None:
        """dR with A'^T dR + h = slack, slack zero except on the K contacts ``open_set``.

        dR(sigma) = A'_{-R}^{-T} (sigma - h)_{rest} satisfies the kept rows; the K unknown slacks
        sigma_Q follow from the K removed rows (a K x K system): no new factorisation.
        """
        m = self.f0.size
        a_r = self.a[:, self.removed].T  # (K, N_f): rows of A'^T that the LU left out
        x0 = self.lu.solve(-self.h[rest], trans="T")
        r0 = a_r @ x0 + self.h[self.removed]
        basis, resp = [], []
        for q in open_set:
            e = np.zeros(m)
            e[q] = 1.0
            xq = self.lu.solve(e[rest], trans="T")
            basis.append(xq)
            resp.append(a_r @ xq - e[self.removed])
        try:
            sigma = np.linalg.solve(np.column_stack(resp), -r0)
        except np.linalg.LinAlgError:
            return None
        if sigma.min() < -1e-9 * max(np.abs(self.h).max(), 1e-300):
            return None
        return x0 + np.column_stack(basis) @ sigma

    def strain_mode(self, net: ContactNetwork, strain_load: np.ndarray, box: float,
                    cell_length: float) -> tuple[np.ndarray, np.ndarray] | None:
        """A first-order floppy motion (dR, eps) with Tr eps = 0 along the random strain load, or None
        when no strain is orthogonal to the trace and to every self-stress's stress (module docstring).

        Parameters
        ----------
        net : ContactNetwork
            The network the backbone was built from.
        strain_load : numpy.ndarray of float, shape (d(d+1)/2,)
            The random strain load, in the component order of
            :func:`hardpack.jamming.rigidity.strain_pairs`.
        box : float
            LP box: the projected strain is scaled so that its largest component is box / cell_length.
        cell_length : float
            Scale L of the strain bound (:func:`hardpack.jamming.ideal.cell_length`).

        Returns
        -------
        tuple of (numpy.ndarray, numpy.ndarray) or None
            (displacement dR (N, d), zero on the coordinates without variables; strain eps (d, d),
            symmetric and traceless), or None.
        """
        d = net.dim
        coef = strain_coefficients(net)[self.contacts]  # (M, s): A_eps^T
        trace = np.array([1.0 if p == q else 0.0 for p, q in strain_pairs(d)])
        q, _ = np.linalg.qr(np.column_stack([trace, coef.T @ self.null]))
        eps_hat = np.asarray(strain_load, dtype=float)
        eps_hat = eps_hat - q @ (q.T @ eps_hat)
        if np.linalg.norm(eps_hat) <= 1e-12 * np.linalg.norm(strain_load):
            return None  # e.g. d = 1, or more self-stresses than strain components
        eps_hat *= box / (cell_length * np.abs(eps_hat).max())
        rhs = -coef @ eps_hat
        rest = np.setdiff1d(np.arange(self.f0.size), self.removed)
        x = self.lu.solve(rhs[rest], trans="T")
        disp = np.zeros(self.free.size)
        disp[self.free] = x
        disp = disp.reshape(-1, d)
        return disp, strain_tensor(eps_hat, d)


def _uniform_self_stress(null: np.ndarray) -> np.ndarray | None:
    """max t s.t. N alpha >= t, mean(N alpha) = 1: the most uniform self-stress (Donev LP 5.9 in
    the K coordinates alpha); None unless it is strictly positive."""
    m, k = null.shape
    if k == 1:
        f = null[:, 0] * m / null[:, 0].sum()
        return f if f.min() > 0 else None
    c = np.r_[np.zeros(k), -1.0]
    a_ub = np.column_stack([-null, np.ones(m)])  # t - N alpha <= 0
    a_eq = np.r_[null.sum(axis=0), 0.0][None, :]
    try:
        res = solve_lp(c, A_ub=a_ub, b_ub=np.zeros(m), A_eq=a_eq, b_eq=[m],
                       bounds=[(None, None)] * k + [(None, 1.0)])
    except LPFailure:
        return None
    if res.x[-1] <= 1e-9:
        return None
    return null @ res.x[:k]
