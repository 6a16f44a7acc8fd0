"""Numba kernels of ellipsoid (3D) and ellipse (2D) MD in a fixed general (sheared) periodic cell,
the windows of the deforming-cell driver (:mod:`hardpack.md.deforming`).

The event loop is the one of the sphere deforming-cell kernel (:mod:`hardpack.md._deforming_kernel`:
lists of (partner, lattice image) entries of the overlapping bounding spheres (Donev 2006, sec.
3.3.2), so a small or sheared cell holds several images of one partner, found on the same linked
cell grid of the bounding-sphere centres
(:func:`hardpack.md._deforming_kernel.list_particle_grid`: a complete build O(N), the rebuild of
one list O(1) in a large cell), and a bounding-sphere exit re-wraps the particle into the cell and
moves its centre to its new grid cell); the particle state, the pair prediction (trace event
location of the Perram-Wertheim potential, best first over the neighbours:
:func:`hardpack.md._ellipsoid_kernel._predict`) and the collision law
(:func:`hardpack.md._ellipsoid_kernel.collide_at`) are the ellipsoid engine's (Donev 2006, sec.
3.5). A list entry is j << cbits | code with the image vectors H n in a table padded to 2^cbits
rows (the ellipsoid kernel's entry format); the predicted partner does not say which image it
collides with, so the collision takes the listed image of the partner with the smallest
zeta (the one in contact: the others do not overlap).

**Stress.** Besides the scalar virial the window accumulates the collisional virial tensor
sum_coll r_ij (x) J_ij, r_ij = x_j - x_i the CENTRE separation and J_ij = J n the impulse on j
(along the contact normal n, not along r_ij), and W = sum_coll t_c Delta(sum_i v_i v_i^T), from
which the driver gets the time integral of the translational kinetic tensor, K_end t - W. The
centre separation is right for non-central contact forces: the momentum flux through a plane of
a system of rigid bodies is carried by their centres of mass (the molecular virial; Allen and
Tildesley 1987, sec. 2.4: the pressure of rigid molecules from the centre-of-mass virial with the
total force on each molecule), the point where a contact force acts on a body only moves
angular momentum within it. The tensor sum r_ij J n^T is not symmetric for one collision (r_ij is
not along n), its antisymmetric part is the torque sum, zero on average in a steady state; the
driver uses the symmetric part.

**Own images.** A particle also collides with its own images x_i + H n, n != 0 (in a small cell
they are real neighbours: with N = 1 they are the only ones). Each pair of images +-n is listed
once, as the entry (i, n) in i's own list (n the image with the larger code), out to the same
bounding-sphere reach as the other pairs; the prediction is the ordinary pair prediction of i
against its shifted self (both bodies share the state row: same velocity, orientation and spin).
Derived here for the collision (:func:`self_collide`): in the periodic system i touches i + H n
and, by periodicity, i - H n at the same moment, the contact points at +-r / 2 from its centre
(r = H n; the two bodies are point symmetric about the midpoint) with normals +-n. The impulses
-J n from the first contact and +J n from the second cancel on the translation, so the centre
velocity of i never changes and the relative translation of i and its image is 0; the torques
add, (r / 2) x (-J n) + (-r / 2) x (J n) = -J r x n, so w_i -= J (r x n) / I_i. The normal
contact velocity is v_n = n . (w x (-r)) - g n . r = -w . (r x n) - g n . r (the spin term is
that of the general law, w x (r_C - r_B) - w x (r_C - r_A) = w x (r_A - r_B), the growth term
likewise), and it changes by J |r x n|^2 / I_i, so J = -2 v_n I_i / |r x n|^2 reverses it (the
general law's denominator 2 + |r_A x n|^2 / I_A + |r_B x n|^2 / I_B would be wrong here: there is
no translational response, and both lever arms turn the same body). Without growth the
rotational energy, -J w . (r x n) + J^2 |r x n|^2 / (2 I_i), is unchanged; the translational
momentum and energy are untouched. The contact belongs to one pair per cell, so it adds
r (x) J n to the virial tensor and r . n J to the scalar virial once, and nothing to W. When
r x n = 0 (spheres, or a spheroid whose contact normal lies along the centre line) no rotation
can relieve an approaching self-contact: only the cell can, and the window ends with status
SELF_IMAGE at that time.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hardpack.events.heap import heap_set
from hardpack.geometry.neighbours.grid import image_cell, next_cell
from hardpack.md import _deforming_kernel as dk
from hardpack.md import _ellipsoid_kernel as ek
from hardpack.md._kernel import A_T, A_VIRIAL, end_window, kinetic_step

#: integer counters (after :mod:`hardpack.md._deforming_kernel`'s): CHECK events, collisions of a
#: particle with its own image (also counted in I_COLL)
I_CHECK = dk.N_COUNTERS
I_SELF = dk.N_COUNTERS + 1
N_COUNTERS = dk.N_COUNTERS + 2
#: float accumulators of :mod:`hardpack.md._kernel` (A_T, A_VIRIAL, A_KEINT, A_KE, A_TKE) and the
#: contact-function evaluations
A_EVAL = 5
N_ACC = 6


def code_bits(m: int) -> int:
    """Bits of an image code for a table of m images: the smallest c with 2^c >= m.

    Parameters
    ----------
    m : int
        Number of images.

    Returns
    -------
    int
        c.
    """
    return max(1, int(m - 1).bit_length())


def padded_image_table(lattice: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, int]:
    """Image vectors H n (:func:`hardpack.md._deforming_kernel.image_table`) in a table padded with
    zero rows to 2^cbits rows, and cbits.

    Parameters
    ----------
    lattice : numpy.ndarray of float, shape (d, d)
        The cell H, lattice vectors as columns.
    M : numpy.ndarray of int64, shape (d,)
        Image ranges (:func:`hardpack.md._deforming_kernel.image_ranges`).

    Returns
    -------
    img : numpy.ndarray of float64, shape (2^cbits, d)
        Rows 0 .. m - 1 the images in code order, the rest zeros (never listed).
    cbits : int
        Bits of an image code.
    """
    table = dk.image_table(np.ascontiguousarray(lattice, dtype=float), M)
    cbits = code_bits(table.shape[0])
    img = np.zeros((1 << cbits, table.shape[1]))
    img[: table.shape[0]] = table
    return img, cbits


@njit(cache=True)
def _stress_step(P, i, j, t, jimp, ws, vir, kw):
    """Add one collision's terms to the virial tensor (r_ij (x) J n, module docstring) and to
    kw = sum t_c Delta(v v^T), from the centres ws[0], ws[1], the unit normal ws[5] and the
    velocities after the collision in P."""
    d = vir.shape[0]
    cv = d
    xa, xb, n = ws[0, :d], ws[1, :d], ws[5, :d]
    for a in range(d):
        ra = xb[a] - xa[a]
        for b in range(d):
            vir[a, b] += ra * jimp * n[b]
    # v_i = v_i' + J n, v_j = v_j' - J n:  Delta(v v^T) = -+ J (v' n^T + n v'^T) - J^2 n n^T
    for a in range(d):
        for b in range(d):
            dki = -jimp * (P[i, cv + a] * n[b] + n[a] * P[i, cv + b]) - jimp * jimp * n[a] * n[b]
            dkj = jimp * (P[j, cv + a] * n[b] + n[a] * P[j, cv + b]) - jimp * jimp * n[a] * n[b]
            kw[a, b] += t * (dki + dkj)


@njit(cache=True)
def list_self(i, bs, img, m0, cbits, nb, nn):
    """Append to i's list every own image whose bounding sphere overlaps i's (|H n| < 2 R_i, n != 0),
    one entry i << cbits | code per pair +-n (the code above the centre's; the table ``img`` of
    m0 images is point symmetric, code m0 - 1 - c holds -n); returns OVERFLOW when the list is
    full, else 0."""
    d = img.shape[1]
    reach = 2.0 * bs[i, d]
    for c in range((m0 - 1) // 2 + 1, m0):
        r2 = 0.0
        for k in range(d):
            r2 += img[c, k] * img[c, k]
        if r2 < reach * reach:
            if nn[i] >= nb.shape[1]:
                return dk.DeformingStatus.OVERFLOW
            nb[i, nn[i]] = (i << cbits) | c
            nn[i] += 1
    return 0


@njit(cache=True)
def self_collide(P, i, t, sh, kappa, ws, wm):
    """Collision of particle i (advanced to t) with its own image shifted by the lattice vector
    ``sh`` (module docstring, "Own images"): only its spin changes.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows, row i modified in place.
    i : int
        The particle.
    t : float
        Window time of the collision.
    sh : numpy.ndarray of float64, shape (d,)
        The lattice vector r = H n of the image.
    kappa : float
        Relative growth rate of the semiaxes.
    ws, wm : numpy.ndarray
        Scratch of :func:`hardpack.md._ellipsoid_kernel.work_arrays`; on return ws[5, :d] holds the
        unit normal.

    Returns
    -------
    impulse : float
        J > 0 on the image along n; 0 for a pair that does not approach, -1 for an approaching
        contact with r x n = 0 (no rotation can relieve it).
    virial : float
        r . n J.
    """
    d = sh.shape[0]
    _, _, _, _, _, cw, cii, _ = ek.columns(d)
    _, zdot, lam = ek.pair_zeta(P, i, i, sh, t, kappa, 0.5, ws, wm)
    n = ws[5, :d]
    nrm = 0.0
    for k in range(d):
        nrm += n[k] * n[k]
    nrm = np.sqrt(nrm)
    rn = 0.0
    for k in range(d):
        n[k] /= nrm
        rn += sh[k] * n[k]
    vn = zdot / (2.0 * lam * (1.0 - lam) * nrm)
    if not vn < 0.0:
        return 0.0, 0.0
    c = ws[2]
    cc = ek._cross_n(sh, n, c)
    if cc <= 1e-24 * rn * rn:
        return -1.0, 0.0
    jimp = -2.0 * vn / (cc * P[i, cii])
    nw = 3 if d == 3 else 1
    for k in range(nw):
        P[i, cw + k] -= jimp * P[i, cii] * c[k]
    return jimp, rn * jimp


@njit(cache=True)
def _partner_image(P, i, j, t, kappa, nb, nn, img, cbits, ws, wm):
    """Code of the listed image of j (both advanced to t, growing at ``kappa``) that the collision
    at t is with, -1 if j is not listed.

    The prediction names the partner j, not its image, and in a small cell i can touch several
    images of j at once, one approaching and others separating (with two particles per cell j's
    images at r and -r from i have equal zeta). A predicted collision approaches (zeta_dot < 0,
    the sign of the collision law's v_n), so the image taken is the approaching one of the
    smallest zeta: the predicted one, or one at most as far that approaches too (a contact a
    hair early); when none approaches, the image of the smallest zeta (a graze). Taking the
    smallest zeta alone can pick a touching image that separates (two images within 1e-11 of
    contact occur), which the collision law skips as a graze while the same collision is
    predicted again at the same time. Images farther than twice the sum of the bounding radii
    grown to t cannot touch and are skipped; the radii must be those at t, not at the window's
    start, or a fast-growing pair's contact image is skipped in the same way.
    """
    d = img.shape[1]
    _, _, cr, _, _, _, _, _ = ek.columns(d)
    cmask = (1 << cbits) - 1
    sh = ws[9, :d]
    best = np.inf
    code = -1
    best_in = np.inf
    approaching = -1
    far = ((P[i, cr] + P[j, cr]) * (1.0 + kappa * t)) ** 2 * 4.0  # (twice the grown radii sum)^2
    for e in range(nn[i]):
        if nb[i, e] >> cbits != j:
            continue
        c = nb[i, e] & cmask
        d2 = 0.0
        for k in range(d):
            sh[k] = img[c, k]
            dx = P[j, k] + sh[k] - P[i, k]
            d2 += dx * dx
        if code >= 0 and d2 >= far:
            continue
        z, zdot, _ = ek.pair_zeta(P, i, j, sh, t, kappa, 0.5, ws, wm)
        if z < best:
            best = z
            code = c
        if zdot < 0.0 and z < best_in:
            best_in = z
            approaching = c
    return approaching if approaching >= 0 else code


@njit(cache=True)
def run_events(P, H, Hinv, M, img, cbits, cfac, reach, n_cells, cstr, kappa, eps_f, skin, bs, nb, nn, mark, cnt,
               ep, ec, hkey, heap, hpos, tins, touts, done, pst, vir, kw, acc, iacc, coll_target, t_cap):
    """One window of ellipsoid MD in the fixed cell H from a synchronisation point (all particle
    times 0, centres wrapped into the cell): build all lists, predict, process events until
    ``coll_target`` collisions or ``t_cap``.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (:mod:`hardpack.md._ellipsoid_kernel`), modified in place.
    H, Hinv : numpy.ndarray of float64, shape (d, d)
        The cell (lattice vectors as columns) and its inverse.
    M : numpy.ndarray of int64, shape (d,)
        Image ranges (:func:`hardpack.md._deforming_kernel.image_ranges`).
    img : numpy.ndarray of float64, shape (2^cbits, d)
        Image vectors (:func:`padded_image_table`).
    cbits : int
        Bits of an image code.
    cfac : numpy.ndarray of float64, shape (d,)
        Row norms of H^-1.
    reach : float
        Largest bounding-sphere diameter the image table covers (M = image_ranges(H, reach)): a
        larger bounding sphere ends the window with status SELF_IMAGE (the driver enlarges the
        table and repeats the window).
    n_cells, cstr : numpy.ndarray of int64, shape (1, d)
        Cells per lattice direction of the grid of bounding-sphere centres that the lists are built
        from (:func:`hardpack.md._deforming_kernel.list_particle_grid`; any counts >= 1 give the same
        lists, cells about as wide as the largest bounding diameter the fewest tests) and their
        flat-index strides.
    kappa : float
        Relative growth rate of the semiaxes.
    eps_f : float
        Trace tolerance (:data:`hardpack.md._ellipsoid_kernel.EPS_F`).
    skin : numpy.ndarray of float64, shape (N,)
        Bounding-sphere skins.
    bs, nb, nn, mark, cnt, ep, ec, hkey, heap, hpos
        Bounding spheres, lists and event heap as in :func:`hardpack.md._deforming_kernel.run_events`
        (no image array: the image is found at the collision).
    tins, touts, done, pst
        Scratch of :func:`hardpack.md._ellipsoid_kernel._predict`, one row per list slot.
    vir, kw : numpy.ndarray of float64, shape (d, d)
        Outputs (zeroed here): sum r_ij (x) J_ij and sum t_c Delta(sum v v^T) (module docstring).
    acc : numpy.ndarray of float64, shape (N_ACC,)
        acc[A_KE] enters the translational kinetic energy; outputs A_T (end time), A_VIRIAL,
        A_KEINT (time integral of the translational kinetic energy), A_EVAL.
    iacc : numpy.ndarray of int64, shape (N_COUNTERS,)
        Counters of :mod:`hardpack.md._deforming_kernel`, I_CHECK and I_SELF (added to).
    coll_target : int
        Stop after this many collisions.
    t_cap : float
        Stop before the first event later than this window time.

    Returns
    -------
    int
        A :class:`hardpack.md._deforming_kernel.DeformingStatus`; SELF_IMAGE also for an
        approaching self-contact that no rotation can relieve (module docstring; acc[A_T] its time);
        STALLED after a long run of events at one time (acc[A_T] that time).
    """
    n = P.shape[0]
    d = H.shape[0]
    _, ct, cr, _, _, _, _, _ = ek.columns(d)
    m0 = 1
    for k in range(d):
        m0 *= 2 * M[k] + 1
    mul = 1 << cbits
    strides = np.ones(d, dtype=np.int64)
    for k in range(1, d):
        strides[k] = strides[k - 1] * (2 * M[k - 1] + 1)
    ws, wm = ek.work_arrays(d)
    ww, wq = ek.wall_arrays(d)
    wspec = np.zeros(d + 1)
    scratch = np.empty(4)
    wrap = np.empty(d)  # scratch of wrap_one
    vir[:, :] = 0.0
    kw[:, :] = 0.0
    nn[:] = 0
    mark[:] = 0
    hpos[:] = -1
    cnt[:] = 0
    upd = np.empty(2, dtype=np.int64)
    head = np.empty(n_cells[0].prod(), dtype=np.int64)
    nxt = np.empty(n, dtype=np.int64)
    cell_of = np.empty(n, dtype=np.int64)
    gwrap = np.empty((n, d), dtype=np.int64)
    gsw = np.empty((n, d))
    ent = np.empty(nb.shape[1], dtype=np.int64)
    rmax = 0.0  # largest bounding radius in the grid
    for i in range(n):
        for k in range(d):
            bs[i, k] = P[i, k]
        bs[i, d] = P[i, cr] + skin[i]
        rmax = max(rmax, bs[i, d])
    dk.link_cells(bs, Hinv, n_cells, cstr, head, nxt, cell_of, gwrap, gsw)
    for i in range(n):
        st = dk.list_particle_grid(i, i, bs, H, Hinv, M, strides, nb, nn, m0, mul, cfac, reach, rmax, n_cells, cstr,
                                   head, nxt, gwrap, gsw, ent)
        if st == 0:
            st = list_self(i, bs, img, m0, cbits, nb, nn)
        if st != 0:
            return st
    hsize = 0
    for i in range(n):
        key, partner = ek._predict(i, 0.0, P, kappa, eps_f, img, bs, nb, nn, tins, touts, done, pst, ws, wm,
                                   np.int64(ek.PERIODIC_CODE), wspec, ww, wq)
        ep[i] = partner
        if partner >= 0:
            ec[i] = cnt[partner]
        hsize = heap_set(hkey, heap, hpos, hsize, i, key)
    t = 0.0
    same = 0
    max_same = ek.STALL_EVENTS + 10 * n
    while True:
        i = heap[0]
        tn = hkey[0]
        if tn > t_cap:
            t = t_cap
            break
        if tn == np.inf:
            acc[A_T] = t
            return dk.DeformingStatus.STUCK
        # progress guard, as in the fixed cell (:data:`hardpack.md._ellipsoid_kernel.STALL_EVENTS`)
        if tn == t:
            same += 1
            if same > max_same:
                acc[A_T] = t
                return dk.DeformingStatus.STALLED
        else:
            same = 0
        t = tn
        iacc[dk.I_EVENTS] += 1
        p = ep[i]
        npred = 1
        upd[0] = i
        if p == ek.EXIT:
            iacc[dk.I_EXIT] += 1
            ek.advance(P, i, t, scratch)
            dk.wrap_one(P, i, H, Hinv, wrap)
            for e in range(nn[i]):  # drop i from its old neighbours' lists (each list once)
                j = nb[i, e] >> cbits
                if j == i or mark[j]:
                    continue
                mark[j] = 1
                q2 = 0
                while q2 < nn[j]:
                    if nb[j, q2] >> cbits == i:
                        nn[j] -= 1
                        nb[j, q2] = nb[j, nn[j]]
                    else:
                        q2 += 1
            for e in range(nn[i]):
                mark[nb[i, e] >> cbits] = 0
            nn[i] = 0
            for k in range(d):
                bs[i, k] = P[i, k]
            bs[i, d] = P[i, cr] * (1.0 + kappa * t) + skin[i]
            rmax = max(rmax, bs[i, d])
            dk.link_one(bs, i, Hinv, n_cells, cstr, head, nxt, cell_of, gwrap, gsw, False)
            st = dk.list_particle_grid(i, n, bs, H, Hinv, M, strides, nb, nn, m0, mul, cfac, reach, rmax, n_cells,
                                       cstr, head, nxt, gwrap, gsw, ent)
            if st == 0:
                st = list_self(i, bs, img, m0, cbits, nb, nn)
            if st != 0:
                acc[A_T] = t
                return st
            cnt[i] += 1  # others' predictions against i used the old image codes
        elif p == ek.CHECK:
            iacc[I_CHECK] += 1
        elif p < 0 or ec[i] != cnt[p]:
            iacc[dk.I_STALE] += 1
        elif p == i:
            ek.advance(P, i, t, scratch)
            code = _partner_image(P, i, i, t, kappa, nb, nn, img, cbits, ws, wm)
            sh = ws[9, :d]
            for k in range(d):
                sh[k] = img[code, k]
            jimp, vr = self_collide(P, i, t, sh, kappa, ws, wm)
            if jimp < 0.0:
                acc[A_T] = t
                return dk.DeformingStatus.SELF_IMAGE
            if jimp > 0.0:
                acc[A_VIRIAL] += vr
                n_ = ws[5, :d]
                for a in range(d):
                    for b in range(d):
                        vir[a, b] += sh[a] * jimp * n_[b]
                cnt[i] += 1
                iacc[dk.I_COLL] += 1
                iacc[I_SELF] += 1
            else:
                iacc[dk.I_GRAZE] += 1
        else:
            j = p
            ek.advance(P, i, t, scratch)
            ek.advance(P, j, t, scratch)
            code = _partner_image(P, i, j, t, kappa, nb, nn, img, cbits, ws, wm)
            sh = ws[9, :d]
            for k in range(d):
                sh[k] = img[code, k]
            jimp, vr, dke = ek.collide_at(P, i, j, t, sh, kappa, ws, wm)
            if jimp > 0.0:
                acc[A_VIRIAL] += vr
                kinetic_step(acc, t, dke)
                _stress_step(P, i, j, t, jimp, ws, vir, kw)
                cnt[i] += 1
                cnt[j] += 1
                iacc[dk.I_COLL] += 1
            else:
                iacc[dk.I_GRAZE] += 1
            upd[1] = j
            npred = 2
        for q in range(npred):
            k = upd[q]
            key, partner = ek._predict(k, t, P, kappa, eps_f, img, bs, nb, nn, tins, touts, done, pst, ws, wm,
                                       np.int64(ek.PERIODIC_CODE), wspec, ww, wq)
            ep[k] = partner
            if partner >= 0:
                ec[k] = cnt[partner]
            hsize = heap_set(hkey, heap, hpos, hsize, k, key)
        if (npred == 2 or p == i) and iacc[dk.I_COLL] >= coll_target:
            break
    end_window(acc, t)
    acc[A_EVAL] = ws[10, 0]
    if t == t_cap:
        return dk.DeformingStatus.DONE_TIME
    return dk.DeformingStatus.DONE_COLLISIONS


@njit(cache=True, inline="always")
def _image_before(j1, n1, j2, n2):
    """True when (j1, n1) comes before (j2, n2) in the order of :func:`near_pairs`: j ascending,
    then the images n with the last component varying slowest (the image-code order)."""
    if j1 != j2:
        return j1 < j2
    for k in range(n1.shape[0] - 1, -1, -1):
        if n1[k] != n2[k]:
            return n1[k] < n2[k]
    return False


@njit(cache=True)
def near_pairs(P, H, Hinv, scale, n_cells, cstr):
    """The pairs i <= j and lattice images n whose centres are closer than ``scale`` times the sum
    of their bounding radii, a particle's own images (i = j, n != 0) once per pair +-n (the n
    whose last non-zero component is positive). Centres need not be wrapped.

    The candidates come from a single-level grid of the centres over the fractional coordinates
    (:func:`hardpack.md._deforming_kernel.link_cells`; the cells within ``scale`` (R_i + max R) of
    i's centre, every (particle, image) in them once, as in
    :func:`hardpack.md._deforming_kernel.strain_limit`), so a call costs O(N) in a large cell.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows at a synchronisation point.
    H, Hinv : numpy.ndarray of float64, shape (d, d)
        The cell and its inverse.
    scale : float
        Reach in units of R_i + R_j.
    n_cells, cstr : numpy.ndarray of int64, shape (1, d)
        Cells per lattice direction of the grid (any counts >= 1 give the same pairs; cells about
        2 ``scale`` max R wide the fewest tests) and their flat-index strides.

    Returns
    -------
    pi, pj : numpy.ndarray of int64, shape (K,)
        The pairs (pi = pj for an own image), sorted by i, then j, then the image n with its last
        component varying slowest.
    pn : numpy.ndarray of int64, shape (K, d)
        The image n of j (r_ij = x_j + H n - x_i).
    """
    n = P.shape[0]
    d = H.shape[0]
    _, _, cr, _, _, _, _, _ = ek.columns(d)
    cfac = dk.cell_heights_inverse(Hinv)
    rmax = 0.0
    for i in range(n):
        rmax = max(rmax, P[i, cr])
    head, nxt, wrap, sw = dk.linked_grid(P, Hinv, n_cells, cstr)
    s, w, ds, lo, hi, wide, c, image, blo, bhi, od, coff = dk.walk_scratch(d)
    r = np.empty(d)
    nv = np.empty(d, dtype=np.int64)
    fcap = 64  # the pairs of one i, before sorting
    fj = np.empty(fcap, dtype=np.int64)
    fn = np.empty((fcap, d), dtype=np.int64)
    cap = 16 * n
    pi = np.empty(cap, dtype=np.int64)
    pj = np.empty(cap, dtype=np.int64)
    pn = np.empty((cap, d), dtype=np.int64)
    count = 0
    for i in range(n):
        dk._fractional(P, i, Hinv, s)
        every = dk._cell_range(s, scale * (P[i, cr] + rmax), cfac, n_cells, w, lo, hi, wide)
        j = i  # every: the candidates are i .. n - 1
        more = not every  # else those of the cells of the range, in turn
        if more:
            for k in range(d):
                c[k] = lo[k]
            j = -1
        found = 0
        while True:
            if every:
                if j >= n:
                    break
            else:
                while j < 0 and more:
                    flat = image_cell(c, n_cells, cstr, coff, 0, image)
                    more = next_cell(c, lo, hi)
                    j = head[flat]
                if j < 0:
                    break
            jj = j
            j = j + 1 if every else nxt[j]
            if jj < i:
                continue
            total = dk._image_range(s, w, sw[jj], wide, image, blo, bhi, od)
            if total > 0:
                reach = scale * (P[i, cr] + P[jj, cr])
                for k in range(d):  # ds = H^-1 (x_j - x_i), written out (through a helper: 1.7x the call)
                    acc = 0.0
                    for q in range(d):
                        acc += Hinv[k, q] * (P[jj, q] - P[i, q])
                    ds[k] = acc
            for _ in range(total):
                for k in range(d):
                    nv[k] = od[k] - wrap[jj, k]
                next_cell(od, blo, bhi)
                if i == jj:  # own image: n != 0 with its last non-zero component positive
                    keep = False
                    for k in range(d):
                        if nv[k] != 0:
                            keep = nv[k] > 0
                    if not keep:
                        continue
                rr = dk._image_vector(H, ds, nv, r)
                if rr >= reach * reach:
                    continue
                if found == fcap:
                    fcap *= 2
                    fj2 = np.empty(fcap, dtype=np.int64)
                    fn2 = np.empty((fcap, d), dtype=np.int64)
                    fj2[:found] = fj[:found]
                    fn2[:found] = fn[:found]
                    fj, fn = fj2, fn2
                fj[found] = jj
                for k in range(d):
                    fn[found, k] = nv[k]
                found += 1
        if count + found > cap:
            cap = 2 * (count + found)
            pi2 = np.empty(cap, dtype=np.int64)
            pj2 = np.empty(cap, dtype=np.int64)
            pn2 = np.empty((cap, d), dtype=np.int64)
            pi2[:count] = pi[:count]
            pj2[:count] = pj[:count]
            pn2[:count] = pn[:count]
            pi, pj, pn = pi2, pj2, pn2
        for a in range(found):  # insertion sort into the output
            b = count + a
            while b > count and _image_before(fj[a], fn[a], pj[b - 1], pn[b - 1]):
                pj[b] = pj[b - 1]
                for k in range(d):
                    pn[b, k] = pn[b - 1, k]
                b -= 1
            pj[b] = fj[a]
            for k in range(d):
                pn[b, k] = fn[a, k]
        pi[count:count + found] = i
        count += found
    return pi[:count], pj[:count], pn[:count]


@njit(cache=True)
def pair_scales(P, H, pi, pj, pn, strain):
    """Perram-Wertheim scaling factor mu = sqrt(1 + zeta) to tangency (> 1 disjoint, < 1
    overlapping; Donev 2006, sec. 2.2.2.1) of each listed pair and image at a synchronisation
    point (:func:`near_pairs`), and the rate d zeta / ds along the affine map of the centres
    r -> r + s ``strain`` r with the orientations fixed: 2 lambda (1 - lambda) n . (strain r)
    (Donev 2006, Eq. 2.21 with the relative centre velocity strain r and no spin or growth).

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows at a synchronisation point (all particle times 0).
    H : numpy.ndarray of float64, shape (d, d)
        The cell.
    pi, pj, pn
        Pairs and images (:func:`near_pairs`).
    strain : numpy.ndarray of float64, shape (d, d)
        The strain E of the rate.

    Returns
    -------
    mu : numpy.ndarray of float64, shape (K,)
        mu of every pair.
    rate : numpy.ndarray of float64, shape (K,)
        d zeta / ds of every pair.
    """
    d = H.shape[0]
    _, _, cr, _, _, _, _, _ = ek.columns(d)
    ws, wm = ek.work_arrays(d)
    sh = np.empty(d)
    out = np.empty(pi.shape[0])
    rate = np.empty(pi.shape[0])
    for q in range(pi.shape[0]):
        i, j = pi[q], pj[q]
        for k in range(d):
            a = 0.0
            for m in range(d):
                a += H[k, m] * pn[q, m]
            sh[k] = a
        z, _, lam = ek.pair_zeta(P, i, j, sh, 0.0, 0.0, P[i, cr] / (P[i, cr] + P[j, cr]), ws, wm)
        out[q] = np.sqrt(max(1.0 + z, 0.0))
        r, n = ws[7, :d], ws[5, :d]
        nu = 0.0
        for k in range(d):
            u = 0.0
            for m in range(d):
                u += strain[k, m] * r[m]
            nu += n[k] * u
        rate[q] = 2.0 * lam * (1.0 - lam) * nu
    return out, rate
