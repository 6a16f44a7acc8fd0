"""Numba kernels of the event-driven (collision-driven) hard-sphere MD engine.

Algorithm (Donev 2006, dissertation secs. 3.2.2.2, 3.3.2 and 3.4), in the "one event per
particle, lazy invalidation" form:

- Every particle i carries ONE predicted event (partner ``ep[i]``) in a 4-ary min-heap whose keys
  (event times) are stored in the heap array itself (``hkey``, ``heap``) with a position index
  ``hpos``, so any particle's key changes in O(log N) and sifting touches few cache lines.
- A predicted collision of i with j stores the collision counter of j at prediction time
  (``ec[i] = cnt[j]``). When it pops and j has collided since (``cnt[j] != ec[i]``), the event is
  stale and i just predicts again (lazy invalidation, instead of Donev's symmetric schedules with
  third-party invalidation, Alg. 5 step 5). Correctness: whenever a particle changes velocity it
  re-predicts against ALL its neighbours, so for every pair the particle that changed last holds a
  prediction no later than the pair's true next collision.
- Neighbour lists with immobile bounding spheres (Donev's NNL, sec. 3.3.2): particle i stays inside
  the sphere ``bs[i]`` (centre bs[i, :d], radius bs[i, d]); particles whose bounding spheres do
  not overlap cannot collide, so collisions are predicted only against the list ``nb[i, :nn[i]]``.
  The extra event "i leaves its bounding sphere" (``ep = EXIT``; the exit time solves
  |dr + v t| = R - a(t) with the radius growth included) rebuilds i's list only (Alg. 10)
  with a hierarchical grid of bounding-sphere centres (Ogarko ch. 2.1): level h holds the
  spheres whose bounding radius is capped at ``rcap[h]``, in ``ncl[h]`` cells per side of width
  >= 2 rcap[h] (flat cell index offset ``coff[h]``), and a rebuild visits, level by level, the
  cells within R_i + rcap[l] of i's centre (3^d on its own level; monodisperse systems have one
  level), skipping cells out of reach. Every cell stores copies of its bounding spheres
  contiguously (``cbs``, slot s of cell c at c * ccap + s, partner index ``cid``; ``slot_of``
  locates a particle's slot), so the scan reads plain arrays instead of chasing linked lists
  (it was latency bound). Each list entry packs the neighbour j and its periodic image as
  j << 2d | code, code = sum_k (n_k + 1) 4^k indexing ``imgvec`` (shifts n in {-1, 0, 1}^d; bit
  operations instead of an integer division in the innermost loop); the image changes only when
  the list of i or j is rebuilt (a position is re-wrapped into the box only then, and the
  bounding centres move only then; in a small box, L < 2 (R_i + R_j) plus the moves of both
  centres, a kept neighbour can change image without a wrap), and the rebuild updates the other
  particle's entry whenever it does.
- Time is measured from the last synchronisation (Alg. 3); radii are a_i(t) = a_i (1 + kappa t)
  with ONE relative growth rate kappa (radii grow in proportion to their size).

Particle state is packed in one row per particle, ``P[i] = (x_0..x_{d-1}, v_0..v_{d-1}, t_i, a_i)``:
position and velocity at the particle's own last update time t_i (Alg. 2 step 5, asynchronous
updates), and its radius at window time 0. Masses are all 1.

Pair collision time (derived here; Donev 2006, sec. 3.2.2.2, says only "the first positive root of
a quadratic"): with r = x_j - x_i, u = v_j - v_i, sigma(t) = sigma_0 + g t, contact
|r + u t|^2 = sigma(t)^2 gives A t^2 + 2 B t + C = 0 with A = u.u - g^2, B = r.u - sigma_0 g,
C = r.r - sigma_0^2. C <= 0 (round-off overlap): collide now if B < 0; if B >= 0 but A < 0 (growth outruns the
separation) the later root (B + sqrt(B^2 - AC)) / (-A) is the re-contact. C > 0: a root exists iff
(B < 0 or A < 0) and B^2 - AC >= 0, and the first one is C / (-B + sqrt(B^2 - AC)) for B < 0 and
(B + sqrt(B^2 - AC)) / (-A) for B >= 0 (the two stable forms of the same root).
For shrinking spheres (kappa < 0) the squared equation also has roots with sigma(t) < 0, i.e.
after t = 1/|kappa|; windows end before 0.5/|kappa| (engine), so such roots are never processed.

Hard walls (Donev 2006, sec. 3.2.2.1 and Ch. 7; compiled only into the wall modes, see ``wmode``):
a flat wall at x_k = 0 is hit when x_k(t) = a(t) (gap rate v_k - adot < 0), at x_k = L_k when
L_k - x_k(t) = a(t); a spherical container of radius R about c when |x(t) - c| = R - a(t)
(:func:`hardpack.events.roots.container_root`). The wall reverses the approach speed along its
outward normal n, w = n.v + adot > 0: v -> v - 2 w n (the wall is infinitely massive; kinetic
energy changes by 2 w adot), and the wall receives momentum 2 w, summed in acc[A_WALL + k]
(flat walls of axis k) or acc[A_WALL] (container). Walled axes have no periodic images and
positions along them are never wrapped. A wall event is stored as ep[i] = WALL with the wall in
ec[i] (2 k or 2 k + 1), and the particle's collision counter is raised so that predictions
against it are invalidated like after a pair collision; wall collisions count towards the
window's collision budget.

Collision law (derived here for growing spheres; Donev 2006, Algorithm 12 steps 4-5, as printed,
with n from A to B, pushes an approaching pair together, so the sign is reversed here):
n = r / |r| at contact, v_n = n.(v_j - v_i) - (adot_i + adot_j) < 0 for an approaching pair; with
equal masses the impulse on j is J = -v_n n (v_j += J, v_i -= J), which reverses the CONTACT
normal velocity v_n -> -v_n. Kinetic energy changes by -v_n g (heating when growing). Collisions
with v_n >= 0 are skipped (mispredicted or grazing, Alg. 12 step 3).
"""

from __future__ import annotations

import enum

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from hardpack.events.heap import heap_set
from hardpack.events.roots import contact_root, container_root, exit_root

EXIT = -1  # event: the particle leaves its bounding sphere
NONE = -2  # nothing predicted (event time inf)
WALL = -3  # event: the particle hits a hard wall (which one: ``ec[i]``)

#: boundary modes of :func:`run_events`, tuples whose LENGTH is a compile-time constant: numba
#: compiles one specialisation per mode and the periodic one has no wall code at all
PERIODIC_MODE = ()
FLAT_WALLS_MODE = (0,)
SPHERE_MODE = (0, 0)



class WindowStatus(enum.IntEnum):
    """How :func:`run_events` ended a window."""

    DONE_COLLISIONS = 0  # the window's collision budget is used up (sync at the last collision time)
    DONE_TIME = 1  # the next event is later than t_cap (sync at t_cap)
    OVERFLOW = 2  # a neighbour list is full: enlarge the capacity and redo the window
    STUCK = 3  # no event can ever happen (nothing moves)
    BOUND_TOO_SMALL = 4  # a particle grew to the bounding-radius cap (window too long)
    CELL_OVERFLOW = 5  # a grid cell is full: enlarge the cell capacity and redo the window
    STALLED = 6  # events repeat without advancing the time (ellipsoid engine: an engine failure)


# float accumulators, acc[...]; acc[A_WALL + k] is the wall momentum of axis k (flat walls) or of
# the container (A_WALL), so acc has A_WALL + d entries
A_T, A_VIRIAL, A_KEINT, A_KE, A_TKE, A_WALL = 0, 1, 2, 3, 4, 5
# integer counters, iacc[...]
I_COLL, I_EVENTS, I_STALE, I_EXIT, I_GRAZE, I_WALL = 0, 1, 2, 3, 4, 5
N_COUNTERS = 6


@njit(cache=True, inline="always")
def kinetic_step(acc, t, dke):
    """Integrate the kinetic energy, constant since acc[A_TKE], up to window time t into
    acc[A_KEINT], then change it by ``dke`` (a collision's or reflection's energy change).

    Parameters
    ----------
    acc : numpy.ndarray of float64, shape (A_WALL + d,)
        The window's float accumulators (module constants A_KEINT, A_KE, A_TKE), modified in place.
    t : float
        Window time of the event.
    dke : float
        Change of the total kinetic energy at time t.
    """
    acc[A_KEINT] += acc[A_KE] * (t - acc[A_TKE])
    acc[A_TKE] = t
    acc[A_KE] += dke


@njit(cache=True, inline="always")
def end_window(acc, t):
    """Close the window's accumulators at window time t (its end time, the kinetic integral).

    Parameters
    ----------
    acc : numpy.ndarray of float64, shape (A_WALL + d,)
        The window's float accumulators, modified in place (A_T, A_KEINT, A_TKE).
    t : float
        Window time at which the window ends.
    """
    acc[A_T] = t
    kinetic_step(acc, t, 0.0)



# --------------------------------------------------------------------------------- prefetch
def _prefetch_intrinsic() -> str | None:
    """Name of LLVM's prefetch intrinsic as this llvmlite spells pointers, or None.

    The name is mangled by the pointer type: ``llvm.prefetch.p0`` with opaque pointers (LLVM >= 15
    as numba uses it), ``llvm.prefetch.p0i8`` with typed pointers (older llvmlite). A tiny module
    calling it must parse and verify with the LLVM numba ships; otherwise prefetching is left out
    (the kernels then run without it, about 10 % slower, with identical results).
    """
    import llvmlite.binding as llvm

    ptr = str(ir.IntType(8).as_pointer())
    name = "llvm.prefetch.p0" if ptr == "ptr" else "llvm.prefetch.p0i8"
    text = (f"declare void @{name}({ptr}, i32, i32, i32)\n"
            f"define void @probe({ptr} %p) {{\n"
            f"  call void @{name}({ptr} %p, i32 0, i32 3, i32 1)\n  ret void\n}}\n")
    try:
        llvm.parse_assembly(text).verify()
    except Exception:  # noqa: BLE001 - any LLVM/llvmlite failure: run without prefetching
        return None
    return name


PREFETCH = _prefetch_intrinsic()


@intrinsic
def prefetch_row(typingctx, arr, idx):
    """Ask the CPU to fetch the cache line of arr[idx] (1-D) or arr[idx, 0] (2-D) (llvm.prefetch:
    read, high temporal locality, data cache). A hint only: results are identical with or without
    it, and it compiles to nothing when :data:`PREFETCH` is None."""
    sig = types.void(arr, idx)

    def codegen(context, builder, signature, args):
        if PREFETCH is None:
            return context.get_dummy_value()
        aryty, idxty = signature.args
        ary = context.make_array(aryty)(context, builder, args[0])
        row = context.cast(builder, args[1], idxty, types.intp)
        zero = context.get_constant(types.intp, 0)
        ptr = cgutils.get_item_pointer(context, builder, aryty, ary, [row] + [zero] * (aryty.ndim - 1),
                                       wraparound=False)
        i8p = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]), PREFETCH)
        builder.call(fn, [builder.bitcast(ptr, i8p), ir.Constant(i32, 0), ir.Constant(i32, 3),
                          ir.Constant(i32, 1)])
        return context.get_dummy_value()

    return sig, codegen


@njit(cache=True, inline="always")
def prefetch_next_events(P, bs, nb, nn, ep, heap, hsize, cbits):
    """Look ahead for an event loop (the sphere and ellipsoid kernels; it is memory-latency bound
    from N ~ 1e4): start loading the rows the next events will need, the particles of the next
    few events, the next particle's neighbours and its partner's neighbours. A hint only.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol)
        Particle state rows (:func:`run_events`; the ellipsoid kernel's wider rows also work).
    bs : numpy.ndarray of float64, shape (N, d + 1)
        Bounding spheres, centre then radius.
    nb : numpy.ndarray of int32 or int64, shape (N, cap)
        Neighbour lists, entries j << cbits | image code.
    nn : numpy.ndarray of int32, shape (N,)
        Length of each neighbour list.
    ep : numpy.ndarray of int32, shape (N,)
        Partner of each particle's predicted event (negative: not a particle).
    heap : numpy.ndarray of int32, shape (N,)
        Particle in each heap slot (4-ary min-heap, slot 0 the next event).
    hsize : int
        Number of particles in the heap.
    cbits : int
        Bits of the image code in a list entry, 2 d.
    """
    for c2 in range(1, min(5, hsize)):
        q = heap[c2]
        prefetch_row(P, q)
        prefetch_row(nb, q)
    q = heap[0]
    prefetch_row(bs, q)
    for m in range(nn[q]):
        prefetch_row(P, nb[q, m] >> cbits)
    p = ep[q]
    if p >= 0:
        prefetch_row(P, p)
        for m in range(nn[p]):
            prefetch_row(P, nb[p, m] >> cbits)


@njit(cache=True, inline="always")
def update_neighbour_list(i, a, P, L, invL, skin, sfac, lvl, rcap, ncl, coff, ccount, cid, cbs, slot_of,
                          bs, nb, nn, mark, oldnb, clo, cspan, codo, wmode, walled):
    """Partial near-neighbour-list update of particle i (Donev 2006, Algorithm 10), shared by the
    sphere and ellipsoid kernels: wrap i's position into the box (not along walled axes), give it
    a new bounding sphere of radius a + skin sfac[i] (capped at its level's ``rcap``) in its grid
    cell, list every overlapping bounding sphere with its periodic image code, and update the
    lists of the new, kept and former neighbours (module docstring). ``a`` is i's current (bounding)
    radius; the position columns P[i, :d] must be at the update time. ``wmode`` (compile-time
    length) and ``walled`` as in :func:`run_events` (a container walls every axis).

    Returns 0, or the :class:`WindowStatus` that ends the window (BOUND_TOO_SMALL,
    CELL_OVERFLOW, OVERFLOW); the caller records the time.

    Parameters
    ----------
    i : int
        The particle whose list is updated.
    a : float
        Its current radius (the ellipsoid kernel: its bounding radius), at the update time.
    P : numpy.ndarray of float64, shape (N, ncol)
        Particle state rows; P[i, :d] is wrapped into the box in place.
    L, invL : numpy.ndarray of float64, shape (d,)
        Box side lengths and their inverses.
    skin : float
        Bounding-sphere skin; the bounding radius is a + skin sfac[i], at most rcap[lvl[i]].
    sfac : numpy.ndarray of float64, shape (N,)
        Relative skin of every particle.
    lvl, rcap, ncl, coff, ccount, cid, cbs, slot_of
        Hierarchical grid, as in :func:`run_events` (ccount, cid, cbs, slot_of modified in place).
    bs, nb, nn, mark
        Bounding spheres, neighbour lists and their scratch marks, as in :func:`run_events`
        (modified in place).
    oldnb : numpy.ndarray of int, shape (cap,)
        Scratch for i's former neighbours.
    clo, cspan, codo : numpy.ndarray of int64, shape (d,)
        Scratch for the cell ranges scanned along each axis.
    wmode : tuple
        Boundary mode (:data:`PERIODIC_MODE`, :data:`FLAT_WALLS_MODE`, :data:`SPHERE_MODE`).
    walled : numpy.ndarray of int8, shape (d,)
        1 for the axes without periodic images.

    Returns
    -------
    int
        0 on success, else the :class:`WindowStatus` that ends the window.
    """
    d = L.shape[0]
    cbits = 2 * d
    cmask = (1 << cbits) - 1
    cback = cmask // 3 * 2  # digit-wise 2 - code: the image code of the reverse pair
    cap = nb.shape[1]
    ccap = cid.shape[0] // ccount.shape[0]  # slots per cell
    nlev = ncl.shape[0]
    nold = nn[i]
    for m in range(nold):  # remember the old neighbours, marked with their image code + 1
        j = nb[i, m] >> cbits
        oldnb[m] = j
        mark[j] = (nb[i, m] & cmask) + 1
    nn[i] = 0
    h = lvl[i]
    c = coff[h]
    stride = 1
    for k in range(d):  # wrap into the box and find the new cell on i's level
        x = P[i, k]
        if (len(wmode) == 0 or walled[k] == 0) and (x < 0.0 or x >= L[k]):
            x -= L[k] * np.floor(x * invL[k])
            if x >= L[k]:
                x -= L[k]
            x = max(x, 0.0)
            P[i, k] = x
        bs[i, k] = x
        gk = int(x * invL[k] * ncl[h, k])
        if gk >= ncl[h, k]:
            gk = ncl[h, k] - 1
        if len(wmode) > 0 and gk < 0:  # a walled axis: no wrap, a round-off crossing
            gk = 0
        c += gk * stride
        stride *= ncl[h, k]
    ri = a + skin * sfac[i]
    if ri > rcap[h]:
        ri = rcap[h]
        if a + 0.25 * skin * sfac[i] >= rcap[h]:
            return WindowStatus.BOUND_TOO_SMALL
    bs[i, d] = ri
    slot = slot_of[i]  # move i's bounding sphere into cell c's slots
    if slot < 0 or slot // ccap != c:
        if ccount[c] >= ccap:
            return WindowStatus.CELL_OVERFLOW
        if slot >= 0:  # leave the old cell: its last entry fills the hole
            old = slot // ccap
            last = old * ccap + ccount[old] - 1
            moved = cid[last]
            cid[slot] = moved
            for k in range(d + 1):
                cbs[slot, k] = cbs[last, k]
            slot_of[moved] = slot
            ccount[old] -= 1
        slot = c * ccap + ccount[c]
        ccount[c] += 1
        cid[slot] = i
        slot_of[i] = slot
    for k in range(d + 1):
        cbs[slot, k] = bs[i, k]
    for lv in range(nlev):  # list every overlapping bounding sphere, level by level
        beta = ri + rcap[lv]  # reach: R_i + R_j <= beta on level lv
        ncells = 1
        for k in range(d):  # the cells within beta of i's centre along each axis
            m = ncl[lv, k]
            lo = int(np.floor((bs[i, k] - beta) * invL[k] * m))
            span = int(np.floor((bs[i, k] + beta) * invL[k] * m)) - lo + 1
            if span >= m:  # all of them (no distance pruning along this axis)
                lo = 0
                span = m
            clo[k] = lo
            cspan[k] = span
            codo[k] = 0
            ncells *= span
        for _ in range(ncells):
            gc = coff[lv]
            stride = 1
            gap2 = 0.0  # squared distance from i's centre to the cell
            for k in range(d):
                m = ncl[lv, k]
                u = clo[k] + codo[k]
                if cspan[k] < m:
                    w = L[k] / m
                    gap = max(u * w - bs[i, k], bs[i, k] - (u + 1) * w, 0.0)
                    gap2 += gap * gap
                gc += (u % m) * stride
                stride *= m
            for k in range(d):  # odometer step
                codo[k] += 1
                if codo[k] < cspan[k]:
                    break
                codo[k] = 0
            if gap2 >= beta * beta:  # no sphere of this cell can reach i's
                continue
            base = gc * ccap
            for sj in range(base, base + ccount[gc]):
                j = cid[sj]
                if j != i:
                    code = 0
                    d2 = 0.0
                    for k in range(d):
                        dx = cbs[sj, k] - bs[i, k]
                        sh = 1
                        if len(wmode) == 0 or walled[k] == 0:  # no images along walls
                            if dx > 0.5 * L[k]:
                                dx -= L[k]
                                sh = 0
                            elif dx < -0.5 * L[k]:
                                dx += L[k]
                                sh = 2
                        code += sh << (2 * k)
                        d2 += dx * dx
                    s = ri + cbs[sj, d]
                    if d2 < s * s:
                        if nn[i] >= cap or nn[j] >= cap:
                            return WindowStatus.OVERFLOW
                        nb[i, nn[i]] = (j << cbits) | code
                        nn[i] += 1
                        back = (i << cbits) | (cback - code)
                        if mark[j] == 0:  # new neighbour
                            nb[j, nn[j]] = back
                            nn[j] += 1
                        else:  # still a neighbour: j's entry changes with the image
                            changed = mark[j] != code + 1
                            mark[j] = 0
                            if changed:
                                for q2 in range(nn[j]):
                                    if nb[j, q2] >> cbits == i:
                                        nb[j, q2] = back
                                        break
    for m in range(nold):  # drop i from the lists of former neighbours
        j = oldnb[m]
        if mark[j] != 0:
            mark[j] = 0
            last = nn[j] - 1
            for q2 in range(last + 1):
                if nb[j, q2] >> cbits == i:
                    nb[j, q2] = nb[j, last]
                    nn[j] = last
                    break
    return 0


@njit(cache=True)
def run_events(P, dims, L, kappa, skin, sfac, imgvec, wmode, walled, wspec, lvl, rcap, ncl, coff, ccount, cid, cbs,
               slot_of, bs, nb, nn, mark, cnt, ep, ec, hkey, heap, hpos, acc, iacc,
               coll_target, t_cap, rebuild_lists, log_pair, log_val):
    """One window: reset the schedule at t = 0, then process events in time order until
    ``coll_target`` collisions happened or the next event is later than ``t_cap`` (Alg. 2).

    Stages of the single loop (:func:`_run_events_loop`, compiled without numba's reference
    counting on the scratch arrays allocated here; the heap update is
    :func:`hardpack.events.heap.heap_set`, inlined):
    (1) only if ``rebuild_lists``: N complete-update steps, each the partial
    NNL update of one particle (wrap, new bounding sphere, re-bin on its grid level, list every
    overlapping bounding sphere already binned; together a complete update, Alg. 9); the
    bounding radius is
    min(a_i(t) + skin sfac_i, rcap_h) on grid level h = lvl[i] (size-dependent skin factors, see
    :meth:`hardpack.md.engine.Engine.skin_factors`). A partial update edits only the
    lists of neighbours gained or lost (``mark`` holds the old ones' image codes + 1), plus those of
    kept ones whose image code changed (a wrap back into the box, or a move of a bounding centre
    across half of a small box). Without ``rebuild_lists``
    the lists, bounding spheres and grid of the previous window are kept (they stay valid across
    a synchronisation); (2) N predictions inserted into the heap (schedule reset, Alg. 4);
    (3) events: stale collision -> re-predict; valid collision -> advance both, collide,
    re-predict both; exit -> partial NNL update (Alg. 10) and re-predict.

    ``acc`` holds float accumulators (A_T current time, A_VIRIAL sum of r_ij . J_ij, A_KEINT time
    integral of the kinetic energy, A_KE current kinetic energy, A_TKE time of the last KE
    update); ``iacc`` integer counters (collisions, events, stale events, exits, grazing skips).
    If ``log_pair`` has rows, collision number c of the window is logged as log_pair[c] = (i, j)
    and log_val[c] = (impulse J on j from i (d components), r_ij . J) (contact forces,
    :mod:`hardpack.md.contacts`); pass (0, 2) / (0, d + 1) arrays to log nothing.
    Returns a status code (module constants).

    Every array is modified in place unless marked read-only; the caller
    (:meth:`hardpack.md.engine.Engine.run_window`) allocates them once and keeps them between
    windows. N particles, d dimensions, n_lev grid levels, n_cells cells over all levels,
    ccap slots per cell, cap entries per neighbour list.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, 2 d + 2)
        Particle state: row i = (x_0..x_{d-1}, v_0..v_{d-1}, t_i, a_i), position and velocity
        at the particle's own last update time t_i (window time) and its radius at window
        time 0 (module docstring). Masses are 1.
    dims : tuple of int
        ``tuple(range(d))``; only its length is used (a compile-time constant for numba).
    L : numpy.ndarray of float64, shape (d,), read-only
        Side lengths of the orthorhombic periodic box.
    kappa : float
        Relative growth rate of the radii, a_i(t) = a_i (1 + kappa t) (< 0 shrinks).
    skin : float
        Bounding-sphere skin of the coming rebuilds (bounding radius a_i(t) + skin sfac_i,
        capped at rcap of the particle's level).
    sfac : numpy.ndarray of float64, shape (N,), read-only
        Relative skin of every particle (:meth:`hardpack.md.engine.Engine.skin_factors`).
    imgvec : numpy.ndarray of float64, shape (4**d, d), read-only
        Periodic shift L n of each image code, code = sum_k (n_k + 1) 4^k.
    wmode : tuple
        Boundary mode, a compile-time constant by its length: PERIODIC_MODE (), FLAT_WALLS_MODE
        (hard walls at x_k = 0 and L_k on the axes flagged in ``walled``) or SPHERE_MODE (a hard
        spherical container ``wspec``); the periodic specialisation contains no wall code.
    walled : numpy.ndarray of int8, shape (d,), read-only
        1 for the axes without periodic images (walled; all of them in a container).
    wspec : numpy.ndarray of float64, shape (d + 1,), read-only
        Container centre and radius R (SPHERE_MODE only).

    lvl : numpy.ndarray of int32, shape (N,), read-only
        Grid / cells: the grid level h of every particle.
    rcap : numpy.ndarray of float64, shape (n_lev,), read-only
        Grid / cells: cap on the bounding radius of the particles of each level.
    ncl : numpy.ndarray of int64, shape (n_lev, d), read-only
        Grid / cells: cells per side of each level (cell width >= 2 rcap[h] unless coarsened).
    coff : numpy.ndarray of int64, shape (n_lev + 1,), read-only
        Grid / cells: offset of each level's first cell in the flat cell index (coff[-1] =
        n_cells).
    ccount : numpy.ndarray of int32, shape (n_cells,)
        Grid / cells: bounding spheres in each cell (reset on a rebuild).
    cid : numpy.ndarray of int32, shape (n_cells * ccap,)
        Grid / cells: particle of each slot; slot s of cell c is c * ccap + s.
    cbs : numpy.ndarray of float64, shape (n_cells * ccap, d + 1)
        Grid / cells: copy of the bounding sphere (centre, radius) of each slot's particle.
    slot_of : numpy.ndarray of int32, shape (N,)
        Grid / cells: slot of each particle's bounding sphere (-1: not binned; reset on a
        rebuild).

    bs : numpy.ndarray of float64, shape (N, d + 1)
        Neighbour lists: bounding sphere of every particle, centre then radius.
    nb : numpy.ndarray of int32 or int64, shape (N, cap)
        Neighbour lists: entries j << 2d | image code of the bounding spheres that overlap
        particle i's.
    nn : numpy.ndarray of int32, shape (N,)
        Neighbour lists: length of each list (reset on a rebuild).
    mark : numpy.ndarray of int32, shape (N,)
        Neighbour lists: scratch of a partial update, image code + 1 of the old neighbours
        (reset at entry; the codes reach 4^d - 1, so a narrower integer would alias codes that
        differ by a multiple of its range and miss a change of image in d >= 5).

    cnt : numpy.ndarray of int32, shape (N,)
        Heap / events: collision counter of every particle (lazy invalidation).
    ep : numpy.ndarray of int32, shape (N,)
        Heap / events: partner of each particle's predicted event (EXIT: leaves its bounding
        sphere; NONE: nothing predicted).
    ec : numpy.ndarray of int32, shape (N,)
        Heap / events: the partner's collision counter at prediction time (``cnt[ep[i]]``).
    hkey : numpy.ndarray of float64, shape (N,)
        Heap / events: key (predicted event time) of heap slot k, in heap order.
    heap : numpy.ndarray of int32, shape (N,)
        Heap / events: particle in heap slot k (4-ary min-heap, :mod:`hardpack.events.heap`).
    hpos : numpy.ndarray of int32, shape (N,)
        Heap / events: heap slot of every particle (reset to -1 at entry).

    acc : numpy.ndarray of float64, shape (5,)
        Outputs: float accumulators A_T (time reached), A_VIRIAL, A_KEINT, A_KE (enter the
        current kinetic energy), A_TKE (enter 0).
    iacc : numpy.ndarray of int64, shape (N_COUNTERS,)
        Outputs: counters I_COLL, I_EVENTS, I_STALE, I_EXIT, I_GRAZE (enter zeros).

    coll_target : int
        Window controls: stop after this many collisions (at the last one's time).
    t_cap : float
        Window controls: stop before the first event later than this window time.
    rebuild_lists : bool
        Window controls: start with a complete rebuild of grid and neighbour lists (stage 1);
        otherwise the previous window's are kept.

    log_pair : numpy.ndarray of int, shape (n_log, 2)
        Outputs: (i, j) of the window's first n_log collisions; n_log = 0 logs nothing.
    log_val : numpy.ndarray of float64, shape (n_log, d + 1)
        Outputs: the impulse J on j from i (d components) and r_ij . J of those collisions.

    Returns
    -------
    int
        Status: DONE_COLLISIONS (``coll_target`` reached; acc[A_T] is the last collision time),
        DONE_TIME (the next event is later than ``t_cap``; acc[A_T] = t_cap), or, for the
        caller to enlarge and redo the window, OVERFLOW (a neighbour list is full),
        CELL_OVERFLOW (a grid cell is full), BOUND_TOO_SMALL (a particle grew to its level's
        bounding-radius cap); STUCK when no event can ever happen.
    """
    d = len(dims)
    cap = nb.shape[1]
    return _run_events_loop(P, dims, L, kappa, skin, sfac, imgvec, wmode, walled, wspec, lvl, rcap,
                            ncl, coff, ccount, cid, cbs, slot_of, bs, nb, nn, mark, cnt, ep, ec,
                            hkey, heap, hpos, acc, iacc, coll_target, t_cap, rebuild_lists,
                            log_pair, log_val,
                            1.0 / L, np.empty(d), np.empty(d), np.empty(d), np.empty(2, dtype=np.int64),
                            np.empty(cap, dtype=np.int64), np.empty(d, dtype=np.int64), np.empty(d, dtype=np.int64),
                            np.empty(d, dtype=np.int64))


@njit(cache=True, _nrt=False)
def _run_events_loop(P, dims, L, kappa, skin, sfac, imgvec, wmode, walled, wspec, lvl, rcap, ncl, coff,
                     ccount, cid, cbs, slot_of, bs, nb, nn, mark, cnt, ep, ec, hkey, heap, hpos, acc,
                     iacc, coll_target, t_cap, rebuild_lists, log_pair, log_val, invL, xi, vi, rv, upd,
                     oldnb, clo, cspan, codo):
    """:func:`run_events` on the scratch arrays it allocates, compiled without numba's reference
    counting: the loop allocates nothing, and no array view in it pays an atomic counter update."""
    d = len(dims)
    n = P.shape[0]
    cbits = 2 * d  # neighbour entry = j << cbits | image code (module docstring)
    cmask = (1 << cbits) - 1
    mark[:] = 0
    hpos[:] = -1
    hsize = 0
    stage = n
    if rebuild_lists:
        ccount[:] = 0
        slot_of[:] = -1
        nn[:] = 0
        stage = 0
    while True:
        npred = 0
        rebuild = False
        wall_hit = False
        if stage < n:  # (1) complete NNL update, one particle per step
            i = stage
            t = 0.0
            rebuild = True
            stage += 1
        elif stage < 2 * n:  # (2) schedule reset
            i = stage - n
            t = 0.0
            upd[0] = i
            npred = 1
            stage += 1
        else:  # (3) events
            i = heap[0]
            t = hkey[0]
            if t > t_cap:
                end_window(acc, t_cap)
                return WindowStatus.DONE_TIME
            if t == np.inf:
                return WindowStatus.STUCK
            iacc[I_EVENTS] += 1
            p = ep[i]
            if p < 0 and (len(wmode) == 0 or p == EXIT):  # leaves its bounding sphere
                iacc[I_EXIT] += 1
                rebuild = True
                upd[0] = i
                npred = 1
            elif len(wmode) > 0 and p == WALL:  # hits a hard wall: reflect (module docstring)
                dti = t - P[i, 2 * d]
                for k in range(d):
                    P[i, k] += P[i, d + k] * dti
                P[i, 2 * d] = t
                adot = P[i, 2 * d + 1] * kappa
                w = 0.0  # approach speed along the outward wall normal, growth included
                kw = 0
                if len(wmode) == 1:  # flat wall ec[i] = 2 k (x_k = 0) or 2 k + 1 (x_k = L_k)
                    kw = ec[i] >> 1
                    for k in range(d):
                        rv[k] = 0.0
                    rv[kw] = 1.0 if ec[i] & 1 else -1.0
                    w = rv[kw] * P[i, d + kw] + adot
                else:  # spherical container: outward normal (x - c) / |x - c|
                    dist2 = 0.0
                    for k in range(d):
                        rv[k] = P[i, k] - wspec[k]
                        dist2 += rv[k] * rv[k]
                    dist = np.sqrt(dist2)
                    if dist > 0.0:
                        for k in range(d):
                            rv[k] /= dist
                            w += rv[k] * P[i, d + k]
                        w += adot
                if w > 0.0:
                    for k in range(d):
                        P[i, d + k] -= 2.0 * w * rv[k]
                    acc[A_WALL + kw] += 2.0 * w
                    kinetic_step(acc, t, 2.0 * w * adot)
                    cnt[i] += 1
                    iacc[I_WALL] += 1
                    wall_hit = True
                else:
                    iacc[I_GRAZE] += 1
                upd[0] = i
                npred = 1
            elif ec[i] != cnt[p]:  # the partner collided since the prediction: stale
                iacc[I_STALE] += 1
                upd[0] = i
                npred = 1
            else:  # binary collision of i and j at time t
                j = p
                dti = t - P[i, 2 * d]
                dtj = t - P[j, 2 * d]
                dist2 = 0.0
                for k in range(d):
                    P[i, k] += P[i, d + k] * dti
                    P[j, k] += P[j, d + k] * dtj
                    dx = P[j, k] - P[i, k]
                    dx -= L[k] * np.floor(dx * invL[k] + 0.5)
                    rv[k] = dx
                    dist2 += dx * dx
                P[i, 2 * d] = t
                P[j, 2 * d] = t
                dist = np.sqrt(dist2)
                g = (P[i, 2 * d + 1] + P[j, 2 * d + 1]) * kappa
                vn = 0.0
                for k in range(d):
                    rv[k] /= dist
                    vn += rv[k] * (P[j, d + k] - P[i, d + k])
                vn -= g
                if vn < 0.0:
                    for k in range(d):
                        dv = vn * rv[k]
                        P[i, d + k] += dv
                        P[j, d + k] -= dv
                    acc[A_VIRIAL] -= vn * dist
                    c = iacc[I_COLL]
                    if c < log_pair.shape[0]:
                        log_pair[c, 0] = i
                        log_pair[c, 1] = j
                        for k in range(d):
                            log_val[c, k] = -vn * rv[k]
                        log_val[c, d] = -vn * dist
                    kinetic_step(acc, t, -(vn * g))
                    cnt[i] += 1
                    cnt[j] += 1
                    iacc[I_COLL] += 1
                else:  # mispredicted / grazing (Alg. 12 step 3): no impulse
                    iacc[I_GRAZE] += 1
                upd[0] = i
                upd[1] = j
                npred = 2

        if rebuild:  # partial NNL update of particle i at time t (Alg. 10)
            dt = t - P[i, 2 * d]
            for k in range(d):
                P[i, k] += P[i, d + k] * dt
            P[i, 2 * d] = t
            status = update_neighbour_list(i, P[i, 2 * d + 1] * (1.0 + kappa * t), P, L, invL, skin, sfac, lvl,
                                           rcap, ncl, coff, ccount, cid, cbs, slot_of, bs, nb, nn, mark,
                                           oldnb, clo, cspan, codo, wmode, walled)
            if status != 0:
                acc[A_T] = t
                return status

        for q in range(npred):  # predict (Alg. 5 with NNLs) and update the heap
            i = upd[q]
            dt = t - P[i, 2 * d]
            ai = P[i, 2 * d + 1]
            grow = 1.0 + kappa * t
            adot = ai * kappa
            rrem = bs[i, d] - ai * grow
            dd = 0.0
            dv = 0.0
            vv = 0.0
            for k in range(d):
                vk = P[i, d + k]
                vi[k] = vk
                xk = P[i, k] + vk * dt
                xi[k] = xk
                dx = xk - bs[i, k]
                dd += dx * dx
                dv += dx * vk
                vv += vk * vk
            best = exit_root(dd, dv, vv, rrem, adot)
            partner = EXIT if best < np.inf else NONE
            wid = 0
            if len(wmode) == 1:  # flat walls: gap x_k - a(t) to x_k = 0, L_k - x_k - a(t) to x_k = L_k
                anow = ai * grow
                for k in range(d):
                    if walled[k]:
                        rate = vi[k] - adot
                        if rate < 0.0:
                            tw = max(xi[k] - anow, 0.0) / -rate
                            if tw < best:
                                best = tw
                                partner = WALL
                                wid = 2 * k
                        rate = -vi[k] - adot
                        if rate < 0.0:
                            tw = max(L[k] - xi[k] - anow, 0.0) / -rate
                            if tw < best:
                                best = tw
                                partner = WALL
                                wid = 2 * k + 1
            elif len(wmode) == 2:  # spherical container: |x - c| = R - a(t)
                dd = 0.0
                dv = 0.0
                for k in range(d):
                    dx = xi[k] - wspec[k]
                    dd += dx * dx
                    dv += dx * vi[k]
                tw = container_root(dd, dv, vv, wspec[d] - ai * grow, adot)
                if tw < best:
                    best = tw
                    partner = WALL
            for m in range(nn[i]):
                e = nb[i, m]
                j = e >> cbits
                im = e & cmask
                dtj = t - P[j, 2 * d]
                rr = 0.0
                ru = 0.0
                uu = 0.0
                for k in range(d):
                    vjk = P[j, d + k]
                    r = P[j, k] + vjk * dtj - xi[k] + imgvec[im, k]
                    u = vjk - vi[k]
                    rr += r * r
                    ru += r * u
                    uu += u * u
                s = ai + P[j, 2 * d + 1]
                tc = contact_root(rr, ru, uu, s * grow, s * kappa, best)
                if tc < best:
                    best = tc
                    partner = j
            key = t + best
            ep[i] = partner
            if partner >= 0:
                ec[i] = cnt[partner]
            elif len(wmode) > 0 and partner == WALL:
                ec[i] = wid
            hsize = heap_set(hkey, heap, hpos, hsize, i, key)

        if stage == 2 * n and hsize > 1:
            prefetch_next_events(P, bs, nb, nn, ep, heap, hsize, cbits)
        if iacc[I_COLL] >= coll_target and npred == 2:
            end_window(acc, t)
            return WindowStatus.DONE_COLLISIONS
        if len(wmode) > 0 and wall_hit and iacc[I_COLL] + iacc[I_WALL] >= coll_target:
            end_window(acc, t)
            return WindowStatus.DONE_COLLISIONS


# --------------------------------------------------------------------------------- sync
@njit(cache=True)
def synchronise(P, dims, t, kappa):
    """Advance every particle to time t, move the radii to a_i (1 + kappa t) and reset the time
    origin (Alg. 3). Returns the total kinetic energy sum_i v_i^2 / 2.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, 2 d + 2)
        Particle state rows (:func:`run_events`), modified in place: positions at t, own times 0,
        radii a_i (1 + kappa t).
    dims : tuple of int
        ``tuple(range(d))``; only its length is used.
    t : float
        Window time of the synchronisation.
    kappa : float
        Relative growth rate of the radii.

    Returns
    -------
    float
        Total kinetic energy sum_i v_i^2 / 2 (unit masses).
    """
    d = len(dims)
    ke = 0.0
    grow = 1.0 + kappa * t
    for i in range(P.shape[0]):
        dt = t - P[i, 2 * d]
        for k in range(d):
            v = P[i, d + k]
            P[i, k] += v * dt
            ke += 0.5 * v * v
        P[i, 2 * d] = 0.0
        P[i, 2 * d + 1] *= grow
    return ke


@njit(cache=True)
def max_overlap(P, dims, imgvec, nb, nn):
    """Largest relative overlap 1 - |r_ij| / (a_i + a_j) over all listed pairs at a sync point (all
    particles at t = 0), and the number of pairs with overlap > 0. Every touching pair is listed,
    because touching spheres have overlapping bounding spheres.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, 2 d + 2)
        Particle state rows at a synchronisation point.
    dims : tuple of int
        ``tuple(range(d))``; only its length is used.
    imgvec : numpy.ndarray of float64, shape (4**d, d)
        Periodic shift of each image code.
    nb : numpy.ndarray of int32 or int64, shape (N, cap)
        Neighbour lists, entries j << 2d | image code.
    nn : numpy.ndarray of int32, shape (N,)
        Length of each neighbour list.

    Returns
    -------
    worst : float
        Largest 1 - |r_ij| / (a_i + a_j) (-inf without listed pairs; <= 0 when nothing overlaps).
    count : int
        Number of listed pairs that overlap.
    """
    d = len(dims)
    worst = -np.inf
    count = 0
    cbits = 2 * d
    for i in range(P.shape[0]):
        for m in range(nn[i]):
            j = nb[i, m] >> cbits
            if j < i:
                continue
            im = nb[i, m] & ((1 << cbits) - 1)
            d2 = 0.0
            for k in range(d):
                dx = P[j, k] + imgvec[im, k] - P[i, k]
                d2 += dx * dx
            ov = 1.0 - np.sqrt(d2) / (P[i, 2 * d + 1] + P[j, 2 * d + 1])
            worst = max(worst, ov)
            if ov > 0.0:
                count += 1
    return worst, count


@njit(cache=True)
def totals(P, dims):
    """(kinetic energy sum v^2/2, sum of radii, sum of radii^d) in a fixed summation order, so
    that a resumed run computes bit-identical values.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, 2 d + 2)
        Particle state rows at a synchronisation point.
    dims : tuple of int
        ``tuple(range(d))``; only its length is used.

    Returns
    -------
    ke : float
        Kinetic energy sum_i v_i^2 / 2.
    s1 : float
        Sum of the radii, sum_i a_i.
    sd : float
        Sum of the d-th powers of the radii, sum_i a_i^d.
    """
    d = len(dims)
    ke = 0.0
    s1 = 0.0
    sd = 0.0
    for i in range(P.shape[0]):
        for k in range(d):
            v = P[i, d + k]
            ke += 0.5 * v * v
        a = P[i, 2 * d + 1]
        s1 += a
        sd += a**d
    return ke, s1, sd
