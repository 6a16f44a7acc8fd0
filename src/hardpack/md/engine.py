"""One MD system in numba arrays, run window by window between synchronisation points.

A *window* starts at a synchronisation point with time t = 0 (Donev Alg. 3): all particles are at
the same time and the schedule is reset (Alg. 4). Events are then processed
(:func:`hardpack.md._kernel.run_events`) until the window's collision budget is spent or a time
cap is reached, and every particle is synchronised again. The bounding-sphere neighbour lists
persist across windows (positions are advanced, never re-wrapped, by a synchronisation); they are
rebuilt completely (Alg. 9) after a spatial sort, when the particles have grown close to the
bounding-radius cap, or when the requested skin no longer fits under it.

If a neighbour list or a grid cell overflows its capacity, or a particle outgrows the cap, the
window is rolled back to its starting positions and velocities and redone after a complete
rebuild (with twice the capacity after an overflow). Every such decision depends only on the
state and on the capacities, which the checkpoint stores, so a restarted run repeats the same
sequence bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours import cell_counts, geometric_levels
from hardpack.md import _kernel as kernel
from hardpack.md._kernel import WindowStatus

#: cells per particle of a level above which its grid is coarsened (dilute systems)
MAX_CELLS_PER_PARTICLE = 2.0
#: skins scale like (a_i + <a>)^-SKIN_SIZE_EXPONENT (see Engine.skin_factors)
SKIN_SIZE_EXPONENT = 1.0
#: ratio of the bounding radii spanned by one grid level (hierarchical grid for wide distributions;
#: geometric cell sizes, :func:`hardpack.geometry.neighbours.geometric_levels`)
LEVEL_RATIO = 2.0
#: cell width of a level in units of its bounding-radius cap: a rebuild scans the cells within
#: R_i + rcap of the centre (3^d on its own level; width 1 with up to 5^d cells was 1.6x slower)
CELL_WIDTH = 2.0
#: head room of the cell width over the largest bounding sphere at the window start
GRID_HEADROOM = 1.05
#: smallest bounding skin (relative to the largest radius) before the box is declared too small
MIN_SHELL = 1e-3
#: rebuild the lists when the radius cap squeezes the requested skin by more than this factor
#: (at 1.05 a shell grown by the adaptive rule takes effect in the next window; at 1.1 the caps of
#: the last rebuild could hold it ~8 % thin until the next spatial sort, measured on UV omega = 10)
SKIN_SLACK = 1.05


@dataclass
class WindowResult:
    """What happened in one window (all times relative to the window start).

    Attributes
    ----------
    duration : float
        Window length in MD time.
    virial : float
        Sum over the collisions of r_ij . J_ij.
    ke_integral : float
        Time integral of the total kinetic energy over the window.
    ke_end : float
        Total kinetic energy at the end, before any rescaling.
    collisions, events, stale, exits, grazing : int
        Pair collisions, events processed, stale (invalidated) events, bounding-sphere exits and
        predicted collisions skipped as grazing (v_n >= 0) in the window.
    max_overlap : float
        Largest relative overlap 1 - r / (a_i + a_j) at the end.
    n_overlapping : int
        Pairs with a positive overlap at the end.
    mean_neighbours : float
        Mean neighbour-list length.
    wall_collisions : int
        Reflections at hard walls.
    wall_momentum : numpy.ndarray of float, shape (d,), or None
        Momentum given to the walls (above).
    """

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
    wall_collisions: int = 0  # reflections at hard walls
    #: momentum given to the walls, sum of |J| over reflections: per walled axis k (flat walls,
    #: both walls of the axis) or in entry 0 (spherical container); zeros without walls
    wall_momentum: np.ndarray | None = None


def _aligned_rows(n: int, width: int) -> np.ndarray:
    """Zeroed (n, width) float64 array whose data start on a 64-byte (cache-line) boundary."""
    buf = np.zeros(n * width + 8)
    offset = (-buf.ctypes.data % 64) // 8
    return buf[offset: offset + n * width].reshape(n, width)


def _cell_capacity(occupancy: float) -> int:
    """Initial slots per grid cell: the mean occupancy plus 4 Poisson standard deviations, plus 2
    (a full cell doubles the capacity and redoes the window)."""
    return int(np.ceil(occupancy + 4.0 * np.sqrt(occupancy) + 2.0))


def image_shifts(codes, d: int) -> np.ndarray:
    """Lattice shifts n in {-1, 0, 1}^d of neighbour-entry image codes sum_k (n_k + 1) 4^k (a
    code with a digit 3 maps to n_k = 2; such codes never occur in the lists).

    Parameters
    ----------
    codes : array_like of int
        Image codes, any shape S.
    d : int
        Dimension.

    Returns
    -------
    numpy.ndarray of int64, shape S + (d,)
        The shifts n.
    """
    codes = np.asarray(codes, dtype=np.int64)
    return (codes[..., None] >> (2 * np.arange(d))) % 4 - 1


def image_vectors(box: np.ndarray) -> np.ndarray:
    """Table of periodic shifts L * n indexed by the image code (:func:`image_shifts`).

    Parameters
    ----------
    box : numpy.ndarray of float, shape (d,)
        Box side lengths L.

    Returns
    -------
    numpy.ndarray of float, shape (4**d, d)
        Row ``code`` is L n of the code's shift n.
    """
    d = len(box)
    return image_shifts(np.arange(4**d), d) * box[None, :]


def wall_arrays(boundary, d: int) -> tuple[tuple, np.ndarray, np.ndarray]:
    """Kernel form of a boundary (:mod:`hardpack.geometry.boundaries`): the mode tuple
    (:data:`hardpack.md._kernel.PERIODIC_MODE`, ``FLAT_WALLS_MODE`` or ``SPHERE_MODE``), the
    walled-axis flags (d,) int8 and the container (centre, radius) (d + 1,) (zeros unless a
    spherical container).

    Parameters
    ----------
    boundary : boundary object or None
        PeriodicBoundary, HardWalls or SphericalContainer; None = periodic.
    d : int
        Dimension.

    Returns
    -------
    mode : tuple
        The kernel's boundary mode.
    walled : numpy.ndarray of int8, shape (d,)
        1 for the axes without periodic images.
    spec : numpy.ndarray of float, shape (d + 1,)
        Container centre and radius.
    """
    kind = "periodic" if boundary is None else boundary.kind
    walled = np.zeros(d, dtype=np.int8)
    spec = np.zeros(d + 1)
    if kind == "periodic":
        return kernel.PERIODIC_MODE, walled, spec
    if kind == "hard_walls":
        walled[list(boundary.axes)] = 1
        return kernel.FLAT_WALLS_MODE, walled, spec
    walled[:] = 1
    spec[:d] = boundary.centre
    spec[d] = boundary.radius
    return kernel.SPHERE_MODE, walled, spec


class Engine:
    """Numba state of N spheres in an orthorhombic box with side lengths ``box``: periodic, or with
    hard walls (``boundary``, a :mod:`hardpack.geometry.boundaries` object; None = periodic).

    Parameters
    ----------
    positions : numpy.ndarray of float, shape (N, d)
        Centres, inside the box.
    velocities : numpy.ndarray of float, shape (N, d)
        Velocities (unit masses).
    radii : numpy.ndarray of float, shape (N,)
        Radii at window time 0.
    box : numpy.ndarray of float, shape (d,)
        Box side lengths.
    capacity : int, optional
        Initial neighbour-list capacity (doubled on overflow).
    boundary : boundary object or None, optional
        Walls of the box (:func:`wall_arrays`); None = periodic.
    """

    def __init__(self, positions: np.ndarray, velocities: np.ndarray, radii: np.ndarray,
                 box: np.ndarray, capacity: int = 32, boundary=None):
        n, d = positions.shape
        self.n, self.d = n, d
        self.box = np.ascontiguousarray(box, dtype=float)
        self.P = _aligned_rows(n, 2 * d + 2)
        self.P[:, :d] = positions
        self.P[:, d:2 * d] = velocities
        self.P[:, 2 * d + 1] = radii
        self.dims = tuple(range(d))  # its length is a compile-time constant in the kernels
        self.imgvec = image_vectors(self.box)
        self.wmode, self.walled, self.wspec = wall_arrays(boundary, d)
        self._no_log_pair = np.zeros((0, 2), dtype=np.int32)
        self._no_log_val = np.zeros((0, d + 1))
        self.init_event_state(capacity)

    def init_event_state(self, capacity: int) -> None:
        """Arrays of the event loop (collision counters, predicted partners, heap, bounding
        spheres, neighbour lists of ``capacity`` entries, grid slots), shared by the sphere and
        ellipsoid engines; the lists and grid are built at the first window.

        Parameters
        ----------
        capacity : int
            Neighbour-list entries per particle (doubled on overflow).
        """
        n, d = self.n, self.d
        self.cnt = np.zeros(n, dtype=np.int32)  # 32-bit integers: less memory traffic
        self.ep = np.zeros(n, dtype=np.int32)
        self.ec = np.zeros(n, dtype=np.int32)
        self.hkey = np.zeros(n)
        self.heap = np.zeros(n, dtype=np.int32)
        self.hpos = np.zeros(n, dtype=np.int32)
        self.bs = np.zeros((n, d + 1))  # bounding spheres: centre, radius
        self.nn = np.zeros(n, dtype=np.int32)
        # image code + 1 of the old neighbours in a partial list update: codes reach 4^d - 1
        self.mark = np.zeros(n, dtype=np.int32)
        self.slot_of = np.zeros(n, dtype=np.int32)
        self.cell_capacity = 0
        #: smallest cell capacity of any grid (doubled after a full cell; part of the run state)
        self.cell_floor = 1
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
        """Total kinetic energy sum_i v_i^2 / 2 (unit masses; the translational one for ellipsoids).

        Returns
        -------
        float
            The kinetic energy.
        """
        return self.totals()[0]

    def sort_spatially(self) -> np.ndarray:
        """Reorder particles along a grid of cells one mean diameter wide (dimension 0 fastest)
        so that neighbours are close in memory; returns the permutation applied (new index -> old
        index). (A Morton order over finer cells was measured slightly slower in 3D.)"""
        ncell = np.maximum(np.floor(self.box / (2.0 * self.radii.mean())).astype(np.int64), 1)
        g = np.floor(self.positions / self.box * ncell).astype(np.int64) % ncell
        strides = np.cumprod(np.concatenate([[1], ncell[:-1]]))
        order = np.argsort(g @ strides, kind="stable")
        self.P[:] = self.P[order]
        self.lists_valid = False
        return order

    def neighbours(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Neighbour-list entries of particle i (in the engine's order).

        Parameters
        ----------
        i : int
            Particle index.

        Returns
        -------
        partners : numpy.ndarray of int64, shape (k,)
            Partner indices.
        shifts : numpy.ndarray of int64, shape (k, d)
            Lattice shift n of each partner's image (the image code decoded by :func:`image_shifts`).
        """
        e = self.nb[i, : self.nn[i]].astype(np.int64)
        return e >> (2 * self.d), image_shifts(e & ((1 << 2 * self.d) - 1), self.d)

    # ----------------------------------------------------------------- set-up helpers
    def alloc_lists(self, capacity: int) -> None:
        """Neighbour lists of entries j << 2d | image code: int32 (half the memory traffic) while
        N 4^d fits, int64 beyond (e.g. N > 5.2e5 in d = 6).

        Parameters
        ----------
        capacity : int
            Entries per particle; the lists are zeroed (invalid until the next rebuild).
        """
        self.capacity = int(capacity)
        dtype = np.int32 if self.n * 4**self.d < 2**31 else np.int64
        self.nb = np.zeros((self.n, self.capacity), dtype=dtype)

    def alloc_cells(self, capacity: int) -> None:
        """Slots for ``capacity`` bounding spheres per grid cell (centre and radius copies).

        The grid (its cell offsets) must exist: called when the bounds are set up for a rebuild.

        Parameters
        ----------
        capacity : int
            Bounding spheres per cell.
        """
        ncells = int(self.coff[-1])
        self.cell_capacity = int(capacity)
        self.ccount = np.zeros(ncells, dtype=np.int32)
        self.cid = np.zeros(ncells * self.cell_capacity, dtype=np.int32)
        self.cbs = np.zeros((ncells * self.cell_capacity, self.d + 1))

    def skin_factors(self) -> np.ndarray:
        """Relative skin of every particle, (2 <a> / (a_i + <a>))^2 (1 when all sizes are equal).

        With equal masses all particles move equally fast, so particle i leaves its bounding
        sphere at a rate ~ v / s_i whatever its size, and each exit costs about the same search;
        but i collides at a rate ~ (a_i + <a>)^2 and each of its predictions scans a list of
        ~ (a_i + <a>)^2 s_i neighbours. Minimising sum_i (1 / s_i + c (a_i + <a>)^4 s_i) gives
        s_i ~ (a_i + <a>)^-2: thin skins for the large spheres, thick ones for the small."""
        a = self.radii
        mean = float(a.mean())
        return (2.0 * mean / (a + mean)) ** SKIN_SIZE_EXPONENT

    def _new_bounds(self, skin: float) -> None:
        """Grid levels, their bounding-radius caps and cells for the coming complete rebuild.

        Particles are put on levels by their bounding radius R = a + skin s_i (s_i from
        :meth:`skin_factors`), in classes of ratio LEVEL_RATIO from the smallest (Ogarko's
        insertion rule with geometric cell sizes, :func:`hardpack.geometry.neighbours.geometric_levels`;
        one level unless the radii differ by more than that; empty classes are no levels, so a
        discrete distribution with gaps between its sizes gets one level per occupied class).
        Level h caps the bounding radii of its particles at rcap_h =
        max_h(a + skin s) GRID_HEADROOM (head room for growth) and has cells of width >= 2 rcap_h
        (at most MAX_CELLS_PER_PARTICLE per particle of the level), so a particle's own level is
        searched in 3^d cells and the other levels in the cells within R_i + rcap_l.
        rcap <= L_min / 4, L_min the shortest PERIODIC box side, keeps every pair to one periodic
        image (L > 2 (R_i + R_j)); a periodic box too small for even a thin skin is refused. Axes
        with walls have no images and set no cap (in a spherical container or a closed box a
        particle may grow to fill the container)."""
        a = self.radii
        amax = float(a.max())
        periodic = self.box[self.walled == 0]
        lmin = float(periodic.min()) if periodic.size else np.inf
        self.sfac = self.skin_factors()
        bound = a + skin * self.sfac
        if min(float(bound.max()) * GRID_HEADROOM, 0.25 * lmin) < amax * (1.0 + MIN_SHELL):
            raise InvalidInputError(
                f"the periodic box is too small for these particles: the largest diameter "
                f"{2 * amax:.4g} must stay below half the shortest periodic box side {lmin:.4g} (so "
                "that a pair touches through one periodic image only); use more particles or a larger box"
            )
        levels = geometric_levels(bound, float(np.prod(self.box)), self.d, LEVEL_RATIO)
        lvl = levels.level
        count = np.bincount(lvl, minlength=levels.n_levels)
        self.rcap = np.minimum(0.5 * levels.cell_sizes * GRID_HEADROOM, 0.25 * lmin)
        ncl = cell_counts(self.box, CELL_WIDTH * self.rcap, count, MAX_CELLS_PER_PARTICLE)
        self.lvl = lvl.astype(np.int32)
        self.ncl = ncl
        self.coff = np.concatenate([[0], np.cumsum(np.prod(ncl, axis=1))]).astype(np.int64)
        cells = np.prod(ncl, axis=1).astype(float)
        #: bounding spheres examined per partial rebuild (cells searched x occupancy, averaged)
        span = np.minimum(np.ceil(2.0 * (self.rcap[:, None, None] + self.rcap[None, :, None])
                                  * ncl[None, :, :] / self.box) + 1, ncl[None, :, :])
        self.candidates = float(count @ (np.prod(span, axis=2) @ (count / cells)) / self.n)
        occupancy = float((count / cells).max())
        self.alloc_cells(max(_cell_capacity(occupancy), self.cell_floor))

    def _room(self) -> float:
        """Largest skin the caps allow every particle: min_i (rcap_h(i) - a_i) / s_i."""
        return float(np.min((self.rcap[self.lvl] - self.radii) / self.sfac))

    def _grid_time(self, kappa: float, eff_skin: float) -> float:
        """Time until some particle comes within a quarter of its skin of its level's cap."""
        if kappa <= 0.0:
            return np.inf
        a = self.radii
        return float(np.min((self.rcap[self.lvl] - 0.25 * eff_skin * self.sfac) / a - 1.0) / kappa)

    # ----------------------------------------------------------------- one window
    def run_window(self, kappa: float, skin: float, coll_target: int, t_cap: float,
                   rebuild: bool = False, log=None) -> WindowResult:
        """Run one window from a synchronisation point (all particles at t = 0) and synchronise
        again at its end, moving radii to their end-of-window size.

        The neighbour lists persist between windows; they are rebuilt completely when asked
        (``rebuild``), after a spatial sort, or when the particles have grown too close to the
        bounding-radius cap (or the requested skin exceeds what the cap allows). Every
        decision depends only on the state, so a restarted run repeats it exactly.

        The event kernel itself is called by :meth:`_run_events` and the result read by
        :meth:`_window_result`, the two places where the sphere and ellipsoid engines differ.

        Parameters
        ----------
        kappa : float
            Relative growth rate (da_i/dt) / a_i at the window start (< 0 shrinks; the window then
            ends before t = 0.5 / -kappa).
        skin : float
            Requested skin of the bounding spheres (length; scaled per particle by
            :meth:`skin_factors` and capped by the grid).
        coll_target : int
            Most collisions in the window.
        t_cap : float
            Longest window time (inf: none).
        rebuild : bool, default False
            Force a complete rebuild of the lists and grid.
        log : tuple of numpy.ndarray, optional
            (pairs (M, 2) int32, values (M, d + 1)) arrays, M >= coll_target, that receive the
            window's collisions (:func:`hardpack.md._kernel.run_events`); not implemented for
            ellipsoids.

        Returns
        -------
        WindowResult
            Duration, virial, kinetic energies, counts and the end-of-window overlap check.

        Raises
        ------
        InvalidInputError
            If the periodic box is too small for the particles (a complete rebuild).
        RuntimeError
            If no event can ever happen, or (ellipsoids, :class:`EngineStalledError`) the event
            loop stalls; the state is then back at the window start.
        """
        if not rebuild and self.lists_valid:
            eff_skin = min(skin, self._room())
            rebuild = eff_skin < skin / SKIN_SLACK or \
                self._grid_time(kappa, eff_skin) < 2.0 * self.last_duration
        else:
            rebuild = True
        if rebuild:
            self._new_bounds(skin)
        start = self.P.copy()
        while True:
            eff_skin = min(skin, self._room())
            cap = min(t_cap, self._grid_time(kappa, eff_skin))
            if kappa < 0.0:  # end shrinking windows before radii could vanish
                cap = min(cap, 0.5 / -kappa)
            self.cnt[:] = 0
            status, acc, iacc = self._run_events(kappa, eff_skin, int(coll_target), float(cap), rebuild, log)
            if status in (WindowStatus.OVERFLOW, WindowStatus.CELL_OVERFLOW, WindowStatus.BOUND_TOO_SMALL):
                self.P[:] = start  # redo the window after a full rebuild
                if status == WindowStatus.OVERFLOW:
                    self.alloc_lists(2 * self.capacity)
                elif status == WindowStatus.CELL_OVERFLOW:
                    self.cell_floor = 2 * self.cell_capacity
                    self.alloc_cells(self.cell_floor)
                else:
                    self._new_bounds(skin)
                rebuild = True
                continue
            if status == WindowStatus.STUCK:
                raise RuntimeError("no event can ever happen: no particle moves and none grows")
            if status == WindowStatus.STALLED:
                self.P[:] = start
                self.lists_valid = False
                self._raise_stalled(acc, iacc)
            break
        self.lists_valid = True
        return self._window_result(acc, iacc, kappa)

    def _run_events(self, kappa: float, eff_skin: float, coll_target: int, cap: float, rebuild: bool,
                    log) -> tuple[WindowStatus, np.ndarray, np.ndarray]:
        """One call of the event kernel: (status, float accumulators, integer counters)."""
        if log is None:
            log = (self._no_log_pair, self._no_log_val)
        acc = np.zeros(kernel.A_WALL + self.d)
        acc[kernel.A_KE] = self.kinetic_energy()
        iacc = np.zeros(kernel.N_COUNTERS, dtype=np.int64)
        status = WindowStatus(kernel.run_events(
            self.P, self.dims, self.box, kappa, eff_skin, self.sfac, self.imgvec, self.wmode,
            self.walled, self.wspec, self.lvl, self.rcap,
            self.ncl, self.coff, self.ccount, self.cid, self.cbs, self.slot_of,
            self.bs, self.nb, self.nn, self.mark, self.cnt, self.ep, self.ec, self.hkey,
            self.heap, self.hpos, acc, iacc, coll_target, cap, rebuild, *log))
        return status, acc, iacc

    def _raise_stalled(self, acc: np.ndarray, iacc: np.ndarray) -> None:
        raise RuntimeError("the sphere event kernel never reports a stalled window")

    def _window_result(self, acc: np.ndarray, iacc: np.ndarray, kappa: float) -> WindowResult:
        """Synchronise every particle to the window's end and summarise the window."""
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
            mean_neighbours=float(self.nn.mean()), wall_collisions=int(iacc[kernel.I_WALL]),
            wall_momentum=acc[kernel.A_WALL:].copy(),
        )

    def rescale_velocities(self, kt: float = 1.0) -> None:
        """Scale all velocities so that kT = 2 KE / (d N) equals ``kt`` (Donev 2006, sec. 3.2.4.1).

        Parameters
        ----------
        kt : float, default 1.0
            Target kinetic temperature (m = 1).
        """
        ke = self.kinetic_energy()
        self.P[:, self.d: 2 * self.d] *= np.sqrt(self.d * self.n * kt / (2.0 * ke))
