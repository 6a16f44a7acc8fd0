"""One MD system in numba arrays, run window by window between synchronisation points.

A *window* starts at a synchronisation point with time t = 0 (Donev Alg. 3): all particles are at
the same time and the schedule is reset (Alg. 4). Events are then processed
(:func:`hardpack.md.kernel.run_events`) until the window's collision budget is spent or a time
cap is reached, and every particle is synchronised again. The bounding-sphere neighbour lists
persist across windows (positions are advanced, never re-wrapped, by a synchronisation); they are
rebuilt completely (Alg. 9) after a spatial sort, when the particles have grown close to the
bounding-radius cap, or when the requested skin no longer fits under it.

If a neighbour list overflows its capacity, or a particle outgrows the cap, the window is rolled
back to its starting positions and velocities and redone after a complete rebuild (with twice the
capacity after an overflow). Every such decision depends only on the state and on the capacity,
which the checkpoint stores, so a restarted run repeats the same sequence bit for bit.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.md import kernel

#: cells per particle above which the bounding-sphere grid is coarsened (dilute systems)
MAX_CELLS_PER_PARTICLE = 4.0
#: head room of the cell width over the largest bounding sphere at the window start
GRID_HEADROOM = 1.05
#: smallest bounding skin (relative to the largest radius) before the box is declared too small
MIN_SHELL = 1e-3
#: rebuild the lists when the radius cap squeezes the requested skin by more than this factor
SKIN_SLACK = 1.1


@dataclass
class WindowResult:
    """What happened in one window (all times relative to the window start)."""

    duration: float  # window length in MD time
    virial: float  # sum over collisions of r_ij . J_ij
    ke_integral: float  # time integral of the total kinetic energy over the window
    ke_end: float  # total kinetic energy at the end (before any rescaling)
    collisions: int
    events: int
    stale: int
    exits: int
    grazing: int
    max_overlap: float  # largest relative overlap 1 - r / (a_i + a_j) at the end
    n_overlapping: int  # pairs with a positive overlap at the end
    mean_neighbours: float


def _pow3(d: int) -> np.ndarray:
    return 3 ** np.arange(d, dtype=np.int64)


def _aligned_rows(n: int, width: int) -> np.ndarray:
    """Zeroed (n, width) float64 array whose data start on a 64-byte (cache-line) boundary."""
    buf = np.zeros(n * width + 8)
    offset = (-buf.ctypes.data % 64) // 8
    return buf[offset: offset + n * width].reshape(n, width)


def image_vectors(box: np.ndarray) -> np.ndarray:
    """Table of periodic shifts L * n for n in {-1, 0, 1}^d, indexed by sum (n_k + 1) 3^k."""
    d = len(box)
    codes = np.arange(3**d)
    n = (codes[:, None] // _pow3(d)[None, :]) % 3 - 1
    return n * box[None, :]


def cell_neighbour_table(ncell: np.ndarray) -> np.ndarray:
    """For every cell of an ncell[0] x ... grid (dimension 0 fastest), the distinct periodic
    neighbour cells (offsets -1, 0, 1 per dimension, de-duplicated when ncell_k < 3)."""
    per_dim = [sorted({o % n for o in (-1, 0, 1)}) for n in ncell]
    offsets = np.array(list(itertools.product(*per_dim)), dtype=np.int64)  # (nst, d)
    total = int(np.prod(ncell))
    strides = np.cumprod(np.concatenate([[1], ncell[:-1]])).astype(np.int64)
    idx = (np.arange(total)[:, None] // strides[None, :]) % ncell[None, :]  # (ncells, d)
    nbr = (idx[:, None, :] + offsets[None, :, :]) % ncell[None, None, :]
    table = (nbr * strides[None, None, :]).sum(axis=2)
    return np.ascontiguousarray(table, dtype=np.int32)


class Engine:
    """Numba state of N spheres in an orthorhombic periodic box with side lengths ``box``."""

    def __init__(self, positions: np.ndarray, velocities: np.ndarray, radii: np.ndarray,
                 box: np.ndarray, capacity: int = 32):
        n, d = positions.shape
        self.n, self.d = n, d
        self.box = np.ascontiguousarray(box, dtype=float)
        self.P = _aligned_rows(n, 2 * d + 2)
        self.P[:, :d] = positions
        self.P[:, d:2 * d] = velocities
        self.P[:, 2 * d + 1] = radii
        self.dims = tuple(range(d))  # its length is a compile-time constant in the kernels
        self.pow3 = _pow3(d)
        self.imgvec = image_vectors(self.box)
        self.cnt = np.zeros(n, dtype=np.int32)  # 32-bit integers: less memory traffic
        self.ep = np.zeros(n, dtype=np.int32)
        self.ec = np.zeros(n, dtype=np.int32)
        self.hkey = np.zeros(n)
        self.heap = np.zeros(n, dtype=np.int32)
        self.hpos = np.zeros(n, dtype=np.int32)
        self.bs = np.zeros((n, d + 1))  # bounding spheres: centre, radius
        self.nn = np.zeros(n, dtype=np.int32)
        self.mark = np.zeros(n, dtype=np.int8)
        self.cell_of = np.zeros(n, dtype=np.int32)
        self.nxt = np.zeros(n, dtype=np.int32)
        self.prv = np.zeros(n, dtype=np.int32)
        self._grid_key = None
        self.rcap = 0.0
        self.lists_valid = False  # neighbour lists, bounding spheres and grid match P
        self.last_duration = 0.0
        self.alloc_lists(capacity)

    # ----------------------------------------------------------------- views of the state
    @property
    def positions(self) -> np.ndarray:
        return self.P[:, : self.d]

    @property
    def velocities(self) -> np.ndarray:
        return self.P[:, self.d: 2 * self.d]

    @property
    def radii(self) -> np.ndarray:
        return self.P[:, 2 * self.d + 1]

    def totals(self) -> tuple[float, float, float]:
        """(kinetic energy, sum of radii, sum of radii^d), summed in a fixed order."""
        ke, s1, sd = kernel.totals(self.P, self.dims)
        return float(ke), float(s1), float(sd)

    def kinetic_energy(self) -> float:
        return self.totals()[0]

    def sort_spatially(self) -> np.ndarray:
        """Reorder particles along the cell grid (dimension 0 fastest) so that neighbours are close
        in memory; returns the permutation applied (new index -> old index)."""
        ncell = np.maximum(np.floor(self.box / (2.0 * self.radii.max())).astype(np.int64), 1)
        g = np.floor(self.positions / self.box * ncell).astype(np.int64) % ncell
        strides = np.cumprod(np.concatenate([[1], ncell[:-1]]))
        order = np.argsort(g @ strides, kind="stable")
        self.P[:] = self.P[order]
        self.lists_valid = False
        return order

    # ----------------------------------------------------------------- set-up helpers
    def alloc_lists(self, capacity: int) -> None:
        """Neighbour lists of entries j * 3^d + image code: int32 (half the memory traffic) while
        N 3^d fits, int64 beyond (e.g. N > 2.9e6 in d = 6)."""
        self.capacity = int(capacity)
        dtype = np.int32 if self.n * 3**self.d < 2**31 else np.int64
        self.nb = np.zeros((self.n, self.capacity), dtype=dtype)

    def _grid(self, rcap: float) -> None:
        """Cell grid of bounding-sphere centres with cell width >= 2 rcap (>= 2 cells per side)."""
        volume = float(np.prod(self.box))
        min_width = max(2.0 * rcap, (volume / (MAX_CELLS_PER_PARTICLE * self.n)) ** (1.0 / self.d))
        ncell = np.maximum(np.floor(self.box / min_width).astype(np.int64), 1)
        key = tuple(ncell)
        if key != self._grid_key:
            self.ncell = ncell
            self.cellnb = cell_neighbour_table(ncell)
            #: bounding spheres examined per partial rebuild (cells searched x mean occupancy)
            self.candidates = self.cellnb.shape[1] * self.n / self.cellnb.shape[0]
            self.head = np.full(int(np.prod(ncell)), -1, dtype=np.int32)
            self._grid_key = key

    def _new_bounds(self, skin: float) -> None:
        """Choose the bounding-radius cap rcap for the coming rebuild (with head room for growth)
        and the matching cell grid. rcap <= L_min / 4 keeps every pair to one periodic image
        (L > 2 (R_i + R_j)); a box too small for even a thin skin is refused."""
        amax = float(self.radii.max())
        lmin = float(self.box.min())
        self.rcap = min((amax + skin) * GRID_HEADROOM, 0.25 * lmin)
        if self.rcap < amax * (1.0 + MIN_SHELL):
            raise InvalidInputError(
                f"the periodic box is too small for these particles: the largest diameter "
                f"{2 * amax:.4g} must stay below half the shortest box side {lmin:.4g} (so that a "
                "pair touches through one periodic image only); use more particles or a larger box"
            )
        self._grid(self.rcap)

    def _grid_time(self, kappa: float, eff_skin: float) -> float:
        """Time until the largest particle comes within a quarter skin of the radius cap."""
        if kappa <= 0.0:
            return np.inf
        amax = float(self.radii.max())
        return ((self.rcap - 0.25 * eff_skin) / amax - 1.0) / kappa

    # ----------------------------------------------------------------- one window
    def run_window(self, kappa: float, skin: float, coll_target: int, t_cap: float,
                   rebuild: bool = False) -> WindowResult:
        """Run one window from a synchronisation point (all particles at t = 0) and synchronise
        again at its end, moving radii to their end-of-window size.

        The neighbour lists persist between windows; they are rebuilt completely when asked
        (``rebuild``), after a spatial sort, or when the particles have grown too close to the
        bounding-radius cap (or the requested skin exceeds what the cap allows). Every
        decision depends only on the state, so a restarted run repeats it exactly.
        """
        amax = float(self.radii.max())
        if not rebuild and self.lists_valid:
            eff_skin = min(skin, self.rcap - amax)
            rebuild = eff_skin < skin / SKIN_SLACK or \
                self._grid_time(kappa, eff_skin) < 2.0 * self.last_duration
        else:
            rebuild = True
        if rebuild:
            self._new_bounds(skin)
        start = self.P.copy()
        while True:
            eff_skin = min(skin, self.rcap - amax)
            cap = min(t_cap, self._grid_time(kappa, eff_skin))
            if kappa < 0.0:  # end shrinking windows before radii could vanish
                cap = min(cap, 0.5 / -kappa)
            self.cnt[:] = 0
            acc = np.array([0.0, 0.0, 0.0, self.kinetic_energy(), 0.0])
            iacc = np.zeros(kernel.N_COUNTERS, dtype=np.int64)
            status = kernel.run_events(
                self.P, self.dims, self.box, kappa, eff_skin, self.rcap, self.imgvec, self.pow3,
                self.ncell, self.cellnb, self.head, self.nxt, self.prv, self.cell_of,
                self.bs, self.nb, self.nn, self.mark, self.cnt, self.ep, self.ec, self.hkey,
                self.heap, self.hpos, acc, iacc, int(coll_target), float(cap), rebuild)
            if status in (kernel.OVERFLOW, kernel.BOUND_TOO_SMALL):  # redo with a full rebuild
                self.P[:] = start
                if status == kernel.OVERFLOW:
                    self.alloc_lists(2 * self.capacity)
                else:
                    self._new_bounds(skin)
                rebuild = True
                continue
            if status == kernel.STUCK:
                raise RuntimeError("no event can ever happen: no particle moves and none grows")
            break
        self.lists_valid = True
        duration = float(acc[kernel.A_T])
        self.last_duration = duration
        ke_end = kernel.synchronise(self.P, self.dims, duration, kappa)
        worst, n_over = kernel.max_overlap(self.P, self.dims, self.imgvec, self.nb, self.nn)
        return WindowResult(
            duration=duration, virial=float(acc[kernel.A_VIRIAL]),
            ke_integral=float(acc[kernel.A_KEINT]), ke_end=float(ke_end),
            collisions=int(iacc[kernel.I_COLL]), events=int(iacc[kernel.I_EVENTS]),
            stale=int(iacc[kernel.I_STALE]), exits=int(iacc[kernel.I_EXIT]),
            grazing=int(iacc[kernel.I_GRAZE]), max_overlap=float(worst), n_overlapping=int(n_over),
            mean_neighbours=float(self.nn.mean()),
        )

    def rescale_velocities(self, kt: float = 1.0) -> None:
        """Scale all velocities so that kT = 2 KE / (d N) equals ``kt`` (Donev sec. 3.3.1)."""
        ke = self.kinetic_energy()
        self.P[:, self.d: 2 * self.d] *= np.sqrt(self.d * self.n * kt / (2.0 * ke))
