"""One MD run: its complete state, window by window (shared by compress and equilibrate).

Units and conventions (used throughout :mod:`hardpack.md`):

- all masses are equal, m = 1 (the Skoge-Donev convention; equilibrium properties such as the
  equation of state do not depend on the masses);
- kT = 1: velocities start Maxwell-Boltzmann and are rescaled to kT = 2 KE / (d N) = 1 at every
  synchronisation point when the particles grow (Donev 2006, sec. 3.2.4.1), so the thermal
  speed is sqrt(kT/m) = 1;
- radii grow linearly in time in proportion to their size, a_i(t) = a_i(0) (1 + kappa t); the
  relative rate of a window is kappa = Gamma / (2 <a>) with <a> the mean radius at the window
  start, so the mean DIAMETER grows at d<D>/dt = Gamma (in units of the thermal speed) all run long.
- boundaries: periodic, hard flat walls on some axes, or a spherical container
  (:mod:`hardpack.geometry.boundaries`; Donev 2006, sec. 3.2.2.1 and Ch. 7). phi is over the
  boundary's volume (the container's for a sphere). The reduced pressure ``Z`` is always the
  collision-virial (bulk) pressure Z = 1 + virial / (2 int KE dt) of the pair collisions with
  V = that volume (Donev 2006, sec. 3.2.4.2; Ch. 7 states no other); it diverges at jamming in a
  container as in a periodic cell and drives the stop criteria. With walls the pressure ON THE
  WALLS, p_w = (momentum given to the walls) / (wall area x time), is recorded as
  ``Z_wall`` = p_w V / (N kT) (kT the window's time average): for an ideal gas of point particles
  Z_wall = 1; finite particles see the accessible volume, and near walls the local pressure
  differs from the bulk one, so Z_wall and Z agree only in the thermodynamic limit.

State saved at a synchronisation point that precedes a spatial sort and complete neighbour-list
rebuild (positions, velocities, radii in the engine's order, the permutation to the caller's order,
counters, the adaptive neighbour shell, the list and cell capacities and the window records) determines the
rest of the run exactly, which makes checkpoint/resume bit-identical.
"""

from __future__ import annotations

import time

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import unit_ball_volume
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, Packing
from hardpack.md.contacts import ContactAccumulator
from hardpack.md.engine import Engine

#: initial bounding-sphere skin in units of the mean radius (R_i = a_i + shell <a>), its adaptive
#: range and step factor
SHELL_START, SHELL_MIN, SHELL_MAX, SHELL_STEP = 0.3, 0.02, 0.7, 1.25
#: target range of the work of neighbourhood exits (candidates examined per exit) relative to the
#: work of predictions (~2.4 predictions per collision, each over the neighbour list)
EXIT_WORK_LOW, EXIT_WORK_HIGH = 0.15, 0.6
#: windows between spatial sorts (each followed by a complete neighbour-list rebuild); checkpoints
#: are written only just before such a window, where the state is complete without the lists
SORT_EVERY = 16

RECORD_FIELDS = (
    "time", "phi", "Z", "phi_J_est", "collisions", "kT", "kT_mean", "events", "stale", "exits",
    "grazing", "max_overlap", "shell", "neighbours", "wall_time", "growth_rate",
)
#: further records of runs with hard walls
WALL_RECORD_FIELDS = ("Z_wall", "wall_collisions")


class OverlapError(RuntimeError):
    """Particles overlap beyond the tolerance at a synchronisation point (an engine failure)."""


def maxwell_boltzmann(n: int, d: int, seed) -> np.ndarray:
    """Velocities from numpy.random.default_rng(seed): Gaussian, zero total momentum (for n >= 2),
    and scaled so that kT = 2 KE / (d N) = 1 exactly (m = 1).

    Parameters
    ----------
    n : int
        Number of particles, >= 1. One particle keeps its momentum (removing the mean would leave
        it at rest; only walls can hold a single particle, and they take momentum anyway).
    d : int
        The dimension.
    seed : int, numpy.random.SeedSequence or None
        Anything :func:`numpy.random.default_rng` accepts.

    Returns
    -------
    numpy.ndarray, shape (n, d)
        The velocities.
    """
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((n, d))
    if n > 1:
        v -= v.mean(axis=0)
    v *= np.sqrt(d * n / np.einsum("ij,ij->", v, v))
    return v


def check_packing(packing: Packing) -> None:
    """Refuse packings the engine cannot run: other shapes, sheared cells, fewer than 2 particles
    in a periodic cell (1 is enough with walls), overlaps or wall crossings.

    Parameters
    ----------
    packing : Packing
        The start packing.

    Raises
    ------
    InvalidInputError
        If the engine cannot run it.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError(f"expected a hardpack Packing, got {type(packing).__name__}")
    if packing.shape.kind != "sphere":
        raise InvalidInputError(f"{packing.shape.name} are not supported by the MD engine yet; it "
                                "handles hard spheres only")
    if not packing.is_orthorhombic:
        raise InvalidInputError(
            "the MD engine supports orthorhombic (diagonal) cells only; this lattice is "
            "sheared. Deforming/sheared cells are not implemented yet: pass a diagonal lattice"
        )
    check_start_configuration(packing)


def check_start_configuration(packing: Packing) -> None:
    """The start checks every MD engine shares: at least 2 particles in a periodic cell (1 is
    enough with walls), every particle inside its walls, no overlaps.

    Parameters
    ----------
    packing : Packing
        The start packing.

    Raises
    ------
    InvalidInputError
        If it has too few particles, a wall crossing or an overlap.
    """
    if packing.n_particles < (2 if packing.boundary.kind == "periodic" else 1):
        raise InvalidInputError("MD in a periodic cell needs at least 2 particles")
    walls = packing.containment_report(DEFAULT_OVERLAP_TOL)
    if walls.n_outside:
        where = "the container wall" if packing.boundary.kind == "spherical_container" else "the boundary"
        raise InvalidInputError(f"the start configuration crosses {where} ({walls}); hard-particle MD "
                                "needs every particle inside its walls")
    report = packing.overlap_report(DEFAULT_OVERLAP_TOL)
    if report.n_overlapping:
        raise InvalidInputError(f"the start configuration has overlapping particles ({report}); "
                                "hard-particle MD needs a non-overlapping start")


class Simulation:
    """State of one run; :meth:`run_window` advances it by one synchronisation window.

    Parameters
    ----------
    packing : Packing
        The start packing of spheres (:func:`check_packing`).
    velocities : numpy.ndarray of float, shape (N, d)
        Start velocities in the packing's order (m = 1).
    growth_rate : float
        Growth rate Gamma = (d<D>/dt) / sqrt(kT/m) of the diameters (0: fixed size, < 0 shrinks).
    overlap_tol : float, optional
        Relative overlap above which a window's end state is refused.
    contact_windows : int, optional
        If > 0, log every collision and keep the per-pair impulse sums of the last
        ``contact_windows`` windows in :attr:`contacts` (:mod:`hardpack.md.contacts`).
    """

    def __init__(self, packing: Packing, velocities: np.ndarray, growth_rate: float,
                 overlap_tol: float = DEFAULT_OVERLAP_TOL, contact_windows: int = 0):
        """contact_windows > 0 logs every collision and keeps the per-pair impulse sums of the
        last ``contact_windows`` windows in :attr:`contacts` (:mod:`hardpack.md.contacts`)."""
        check_packing(packing)
        self._setup(packing, growth_rate, overlap_tol)
        self.engine = Engine(self._engine_positions(packing), velocities, packing.radii, self.box,
                             boundary=self.boundary)
        self.contacts = ContactAccumulator(self.n, self.d, contact_windows) if contact_windows else None

    def _setup(self, packing: Packing, growth_rate: float, overlap_tol: float) -> None:
        """The run state every engine shares: cell, boundary, counters and records (the engine and
        the contact accumulator are the caller's)."""
        self.lattice = np.array(packing.lattice)
        self.boundary = packing.boundary
        self.species = packing.species
        self.box = np.diag(self.lattice).copy()
        self.n, self.d = packing.n_particles, packing.dim
        self._periodic = self.boundary.periodic_axes(self.d)
        self._volume = packing.volume
        self.growth_rate = float(growth_rate)
        self.overlap_tol = float(overlap_tol)
        self.perm = np.arange(self.n)
        self.time = 0.0
        self.collisions = 0
        self.events = 0
        self.windows = 0
        self.shell = SHELL_START
        self.since_sort = SORT_EVERY  # sort (and rebuild the lists) before the first window
        self.wall_time = 0.0
        self.fields = RECORD_FIELDS + (WALL_RECORD_FIELDS if self.boundary.kind != "periodic" else ())
        self.records: dict[str, list] = {k: [] for k in self.fields}
        self._log = None

    # ----------------------------------------------------------------- derived quantities
    @property
    def volume(self) -> float:
        """The boundary's volume: the box, or the container's V_d(R)."""
        return self._volume

    def wall_area(self) -> np.ndarray:
        """Area of the walls that :attr:`Engine.run_window`'s ``wall_momentum`` entries act on:
        both walls of each walled axis k (2 V_box / L_k; 0 for periodic axes), or the container
        surface d V_d(R) / R in entry 0."""
        area = np.zeros(self.d)
        if self.boundary.kind == "spherical_container":
            area[0] = self.d * self._volume / self.boundary.radius
        else:
            walled = ~self._periodic
            area[walled] = 2.0 * np.prod(self.box) / self.box[walled]
        return area

    def phi(self) -> float:
        """Volume fraction V_d(1) sum_i a_i^d / V of the current radii (V: the box, or the container).

        Returns
        -------
        float
            phi.
        """
        return unit_ball_volume(self.d) * self.engine.totals()[2] / self.volume

    def _engine_positions(self, packing: Packing) -> np.ndarray:
        """The packing's centres in the engine's box frame: wrapped along the periodic axes, as
        they stand along walled ones (and in a container)."""
        positions = packing.fractional() * self.box
        positions[:, ~self._periodic] = packing.positions[:, ~self._periodic]
        return positions

    def _wrapped_positions(self, inv: np.ndarray) -> np.ndarray:
        """The engine's centres in the caller's order (``inv``, the inverse of :attr:`perm`),
        wrapped into the box along the periodic axes only."""
        pos = self.engine.positions[inv]
        wrapped = pos - np.floor(pos / self.box) * self.box
        wrapped[wrapped >= self.box] = 0.0
        pos[:, self._periodic] = wrapped[:, self._periodic]
        return pos

    def packing(self) -> Packing:
        """The current configuration in the caller's particle order, centres wrapped into the box
        (all particles are synchronised between windows)."""
        inv = np.empty(self.n, dtype=np.int64)
        inv[self.perm] = np.arange(self.n)
        return Packing(self._wrapped_positions(inv), self.engine.radii[inv].copy(), self.lattice,
                       species=self.species, boundary=self.boundary, overlap_tol=self.overlap_tol)

    def velocities(self) -> np.ndarray:
        """Velocities in the caller's particle order.

        Returns
        -------
        numpy.ndarray of float, shape (N, d)
            A copy.
        """
        inv = np.empty(self.n, dtype=np.int64)
        inv[self.perm] = np.arange(self.n)
        return self.engine.velocities[inv].copy()

    # ----------------------------------------------------------------- one window
    def run_window(self, coll_target: int, target_phi: float | None = None) -> dict:
        """Run one window of at most ``coll_target`` collisions (ending exactly when the volume
        fraction reaches ``target_phi`` if that comes first), synchronise, measure, rescale.

        The velocities are rescaled to kT = 1 at the end of a window of a growing or shrinking run.

        Parameters
        ----------
        coll_target : int
            Most collisions in the window.
        target_phi : float, optional
            Volume fraction at which the window ends exactly, if the growth reaches it first (ignored
            without growth or when phi moves away from it).

        Returns
        -------
        dict
            The window record, also appended to :attr:`records`: ``time`` (MD time since the start),
            ``phi``, ``Z`` = pV / (NkT) from the collision virial (inf when no time elapsed),
            ``phi_J_est`` = phi / (1 - d / Z), ``collisions`` and ``events`` (totals), ``kT`` (at the
            end, before the rescaling) and ``kT_mean`` (over the window), ``stale``, ``exits``,
            ``grazing``, ``max_overlap``, ``shell``, ``neighbours``, ``wall_time``, ``growth_rate``,
            ``virial``, ``ke_integral``, and ``Z_wall`` (pressure on the walls, NaN in a periodic cell)
            and ``wall_collisions`` (these two enter :attr:`records` only with walls).

        Raises
        ------
        OverlapError
            If a pair overlaps, or a particle crosses a wall, by more than the overlap tolerance at
            the end of the window.
        InvalidInputError
            If the periodic box is too small for the particles.
        RuntimeError
            If no event can ever happen, or the event loop stalls (ellipsoids).
        """
        start = time.perf_counter()
        eng = self.engine
        rebuild = self.since_sort >= SORT_EVERY
        if rebuild:
            self.perm = self.perm[eng.sort_spatially()]
            self.since_sort = 0
        _, sum_a, sum_ad = eng.totals()
        kappa = self.growth_rate / (2.0 * sum_a / self.n)
        t_cap = np.inf
        if target_phi is not None and kappa != 0.0:
            phi0 = unit_ball_volume(self.d) * sum_ad / self.volume
            t_phi = ((target_phi / phi0) ** (1.0 / self.d) - 1.0) / kappa
            if t_phi >= 0.0:
                t_cap = t_phi
        log = None
        if self.contacts is not None:
            if self._log is None or len(self._log[0]) < coll_target:
                self._log = (np.zeros((coll_target, 2), dtype=np.int32), np.zeros((coll_target, self.d + 1)))
            log = self._log
        res = eng.run_window(kappa, self.shell * sum_a / self.n, coll_target, t_cap, rebuild, log)
        self.since_sort += 1
        if log is not None:
            m = res.collisions
            self.contacts.add(self.perm[log[0][:m]], log[1][:m], res.duration, res.ke_integral)
        if res.max_overlap > self.overlap_tol:
            raise OverlapError(
                f"{res.n_overlapping} pair(s) overlap at the end of window {self.windows}; the "
                f"worst relative overlap is {res.max_overlap:.3e} > tolerance {self.overlap_tol:g}"
            )
        n, d = self.n, self.d
        self.time += res.duration
        self.collisions += res.collisions
        self.events += res.events
        self.windows += 1
        if res.duration > 0.0 and res.ke_integral > 0.0:
            z = 1.0 + res.virial / (2.0 * res.ke_integral)
            kt_mean = 2.0 * res.ke_integral / (d * n * res.duration)
        else:  # no time elapsed: every collision happened at one instant
            z = np.inf
            kt_mean = 2.0 * res.ke_end / (d * n)
        z_wall = np.nan
        if self.boundary.kind != "periodic":
            self._check_walls(res)
            if res.ke_integral > 0.0:  # p_w V / (N kT) with N kT dt = 2 int KE dt / d
                area = self.wall_area()
                p_dt = float(res.wall_momentum[area > 0].sum() / area.sum())
                z_wall = p_dt * self.volume * d / (2.0 * res.ke_integral)
        phi = self.phi()
        phi_j = phi / (1.0 - d / z) if z > d else np.nan
        if self.growth_rate != 0.0:
            eng.rescale_velocities(1.0)
        shell_used = self.shell
        self._adapt_shell(res)
        self.wall_time += time.perf_counter() - start
        record = {
            "time": self.time, "phi": phi, "Z": z, "phi_J_est": phi_j, "collisions": self.collisions,
            "kT": 2.0 * res.ke_end / (d * n), "kT_mean": kt_mean, "events": self.events, "stale": res.stale,
            "exits": res.exits, "grazing": res.grazing, "max_overlap": res.max_overlap, "shell": shell_used,
            "neighbours": res.mean_neighbours, "wall_time": self.wall_time,
            "growth_rate": self.growth_rate, "virial": res.virial, "ke_integral": res.ke_integral,
            "Z_wall": z_wall, "wall_collisions": res.wall_collisions,
        }
        for k in self.fields:
            self.records[k].append(record[k])
        return record

    def _check_walls(self, res) -> None:
        """Raise :class:`OverlapError` when a particle crosses a wall beyond the tolerance."""
        report = self.boundary.containment(self.engine.positions, self.engine.radii, self.lattice,
                                           self.overlap_tol)
        if report.n_outside:
            raise OverlapError(f"at the end of window {self.windows - 1}: {report} > tolerance "
                               f"{self.overlap_tol:g}")

    def _adapt_shell(self, res) -> None:
        """Balance list length against rebuilds: a thicker shell means longer lists (more pair
        predictions), a thinner one more neighbourhood exits (each examining the bounding spheres
        of 3^d cells). The shell grows when exits cost more than EXIT_WORK_HIGH times the
        prediction work (exits * candidates > EXIT_WORK_HIGH * 2.4 * neighbours per collision) and
        shrinks below EXIT_WORK_LOW (Donev tunes mu_cutoff for the same trade-off, sec. 3.4.3).
        In 3D at phi = 0.5 this keeps 0.05-0.2 exits per collision, the timed optimum; in small
        high-d boxes, where a rebuild examines nearly all N spheres, it keeps exits much rarer.
        SHELL_MAX caps the lists of dilute fluids, where exits stay frequent whatever the shell.
        All inputs are counts, so a restarted run adapts identically."""
        if res.collisions == 0:
            return
        exit_work = res.exits * self.engine.candidates / res.collisions
        predict_work = 2.4 * max(res.mean_neighbours, 1.0)
        if exit_work > EXIT_WORK_HIGH * predict_work:
            self.shell = min(self.shell * SHELL_STEP, SHELL_MAX)
        elif exit_work < EXIT_WORK_LOW * predict_work:
            self.shell = max(self.shell / SHELL_STEP, SHELL_MIN)

    # ----------------------------------------------------------------- checkpoint state
    @property
    def checkpoint_ready(self) -> bool:
        """True when the next window starts with a sort and a complete rebuild, so that the state
        below (which has no neighbour lists) continues exactly as this process would."""
        return self.since_sort >= SORT_EVERY

    def state(self) -> dict:
        """Everything needed to continue bit-identically (numpy arrays and scalars)."""
        out = {
            "P": self.engine.P.copy(), "perm": self.perm.copy(), "time": self.time,
            "collisions": self.collisions, "events": self.events, "windows": self.windows,
            "shell": self.shell, "wall_time": self.wall_time, "since_sort": self.since_sort,
            "capacity": self.engine.capacity, "cell_floor": self.engine.cell_floor,
            "growth_rate": self.growth_rate,
        }
        for k, v in self.records.items():
            out["rec_" + k] = np.asarray(v, dtype=float)
        if self.contacts is not None:
            out.update(self.contacts.state())
        return out

    def restore(self, state: dict) -> None:
        """Load a :meth:`state` saved by a run of the same system (checked by the caller).

        Parameters
        ----------
        state : dict
            The arrays and scalars of :meth:`state`.

        Raises
        ------
        InvalidInputError
            If the state is of another system size.
        """
        if state["P"].shape != self.engine.P.shape:
            raise InvalidInputError("checkpoint state does not match this system's size")
        self.engine.P[:] = state["P"]
        self.perm = np.asarray(state["perm"], dtype=np.int64)
        self.time = float(state["time"])
        self.collisions = int(state["collisions"])
        self.events = int(state["events"])
        self.windows = int(state["windows"])
        self.shell = float(state["shell"])
        self.growth_rate = float(state["growth_rate"])
        self.since_sort = int(state["since_sort"])
        self.engine.alloc_lists(int(state["capacity"]))
        self.engine.cell_floor = int(state["cell_floor"])
        self.engine.lists_valid = False
        self.wall_time = float(state["wall_time"])
        self.records = {k: list(np.asarray(state["rec_" + k], dtype=float)) for k in self.fields}
        if self.contacts is not None:
            self.contacts.restore(state)
