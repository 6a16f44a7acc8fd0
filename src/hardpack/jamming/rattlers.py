"""Local jamming and iterative rattler removal (Donev Alg. 13 step 4, LP 4.15).

Source: Donev 2006, dissertation secs. 4.4.3.1 (LP 4.15) and 4.6.1 (Algorithm 13). A particle is locally jammed
when it cannot move while every other particle (including its own periodic images) and the
walls stay fixed. For sphere i with contact normals u_k (towards the neighbours) and gaps h_k the local
LP (4.15) is

    max b_i^T dr_i   s.t.  u_k^T dr_i <= h_k for every contact k,   |dr_i| <= box,

and i is a rattler when ``|dr_i| >= dr_large``. We use two random loads of opposite direction
(the text's option for packings with gaps, sec. 4.4.3.1), which for an ideal packing (h = 0) finds
an escape direction with probability one whenever one exists (recession-cone argument,
sec. 4.3.2.3). The LPs of all tested particles are independent, so they are solved as one
block-separable HiGHS LP per round (both loads in the same LP).

Removing a rattler removes its contacts, which can unjam its neighbours, so the test repeats on
the neighbours of removed particles until nothing changes (sec. 4.4.3.1). Because removing
particles only relaxes the others' constraints, removing a whole round's rattlers at once
gives the same final set as the text's one-at-a-time stack. The cheap rule "fewer than d + 1
contacts" (d vectors cannot positively span R^d, sec. 4.4.3.1) runs first and needs no LP.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from hardpack.jamming.contacts import ContactNetwork
from hardpack.jamming.lp import solve_lp


def neighbours_of(net: ContactNetwork, mask: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Active particles touching a particle in ``mask``.

    Parameters
    ----------
    net : ContactNetwork
        The contact network.
    mask : numpy.ndarray of bool, shape (N,)
        The particles whose neighbours are wanted.
    active : numpy.ndarray of bool, shape (N,)
        Particles still in the packing.

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
        The active particles in contact with one in ``mask``.
    """
    keep = net.among(active | mask)
    out = np.zeros(net.n_particles, dtype=bool)
    out[net.j[keep & mask[net.i]]] = True
    out[net.i[keep & mask[net.j]]] = True
    return out & active


def local_displacements(
    net: ContactNetwork, active: np.ndarray, tested: np.ndarray, load: np.ndarray, box: float
) -> np.ndarray:
    """Largest escape |dr_i| of each ``tested`` particle under the loads +b_i and -b_i, with all
    other ``active`` particles fixed (LP 4.15); NaN for untested particles.

    Parameters
    ----------
    net : ContactNetwork
        The contact network.
    active : numpy.ndarray of bool, shape (N,)
        Particles still in the packing.
    tested : numpy.ndarray of bool, shape (N,)
        Particles tested (each with all others fixed).
    load : numpy.ndarray of float, shape (N, d)
        Loads b_i.
    box : float
        Bound on every displacement component (lengths of the packing).

    Returns
    -------
    numpy.ndarray of float, shape (N,)
        max(|dr_i(+b_i)|, |dr_i(-b_i)|) for the tested particles, NaN elsewhere.
    """
    n, d = net.n_particles, net.dim
    keep = net.among(active)
    i, j, u, h = net.i[keep], net.j[keep], net.normal[keep], net.gap[keep]
    # one inequality u^T dr_p <= h for each (particle p, contact) with p tested:
    # particle i sees +u, particle j sees -u (a self-image contact gives both, a wall contact
    # only the first: its other end is the fixed wall)
    pair = net.wall[keep] < 0
    owner = np.concatenate([i, j[pair]])
    coef = np.concatenate([u, -u[pair]])
    rhs = np.concatenate([h, h[pair]])
    sel = tested[owner]
    owner, coef, rhs = owner[sel], coef[sel], rhs[sel]
    index = -np.ones(n, dtype=np.int64)
    index[tested] = np.arange(int(tested.sum()))
    nt = int(tested.sum())
    nvar = nt * d
    rows = np.repeat(np.arange(len(owner)), d)
    cols = (index[owner][:, None] * d + np.arange(d)).ravel()
    block = sp.csr_matrix((coef.ravel(), (rows, cols)), shape=(len(owner), nvar))
    a_ub = sp.block_diag([block, block], format="csr")  # copy 1: load +b, copy 2: load -b
    b = load[tested].ravel()
    res = solve_lp(
        np.concatenate([-b, b]), A_ub=a_ub, b_ub=np.concatenate([rhs, rhs]), bounds=(-box, box),
    )
    x = res.x.reshape(2, nt, d)
    out = np.full(n, np.nan)
    out[tested] = np.linalg.norm(x, axis=2).max(axis=0)
    return out


def remove_rattlers(
    net: ContactNetwork,
    active: np.ndarray,
    *,
    dr_large: float,
    box: float,
    rng: np.random.Generator,
    use_lp: bool = True,
    recheck: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Iteratively remove particles that are not locally jammed.

    Donev 2006, sec. 4.4.3.1 (LP 4.15) and Algorithm 13 step 4; see the module docstring. The
    contact-count rule (fewer than d + 1 contacts) runs before every LP round.

    Parameters
    ----------
    net : ContactNetwork
        The contacts of the packing.
    active : numpy.ndarray of bool, shape (N,)
        The particles present; not modified in place.
    dr_large : float
        Escape displacement (absolute length) from which a particle is a rattler.
    box : float
        Bound on each displacement component in the local LPs.
    rng : numpy.random.Generator
        Source of the random loads.
    use_lp : bool, default True
        With False only the contact-count rule is applied.
    recheck : numpy.ndarray of bool, shape (N,), optional
        Restricts the first LP round to these particles (default: all active ones); later
        rounds test the neighbours of removed particles.

    Returns
    -------
    active : numpy.ndarray of bool, shape (N,)
        The particles left after removing the rattlers.
    escape : numpy.ndarray of float, shape (N,)
        Local escape displacement |dr_i| of each particle tested by an LP (the last one
        measured); NaN where not measured.
    """
    d = net.dim
    active = active.copy()
    escape = np.full(net.n_particles, np.nan)
    pending = active.copy() if recheck is None else recheck & active
    while True:
        while True:  # contact-count rule: fewer than d + 1 contacts
            few = active & (net.counts(active) < d + 1)
            if not few.any():
                break
            active &= ~few
            pending |= neighbours_of(net, few, active)
        pending &= active
        if not use_lp or not pending.any():
            return active, escape
        load = rng.standard_normal((net.n_particles, d))
        disp = local_displacements(net, active, pending, load, box)
        escape[pending] = disp[pending]
        loose = pending & (disp >= dr_large)
        if not loose.any():
            return active, escape
        active &= ~loose
        pending = neighbours_of(net, loose, active)
