"""Lubachevsky-Stillinger compression in a deforming periodic cell (spheres in any d, ellipsoids
in 3D and ellipses in 2D: :class:`EllipsoidDeformingSimulation`).

Donev 2006, sec. 3.2.4.2 ("iso-stress", a pseudo Parrinello-Rahman scheme for event-driven MD)
makes the lattice vectors (the columns of the cell matrix Lambda) dynamic: at synchronisation
points it sets Lambda' = W^-1 (sigma - P0 I) Lambda, with sigma the measured stress, P0 the
applied pressure and W a cell "mass", and restarts the MD; with P0 = tr(sigma) / d the stress is
kept isotropic at a free volume. This shape freedom is what makes LS packings strictly jammed
(Donev 2006, sec. 4.2.2 and Fig. 4.15: strict jamming lets the lattice deform with Tr eps <= 0).

**Scheme used here** (simplest correct form; the departures from Donev's scheme are marked):

1. A window of MD runs in a FIXED cell (:mod:`hardpack.md._deforming_kernel`); it measures the
   time-averaged stress sigma = (int sum_i v_i v_i^T dt + sum_coll r_ij J_ij^T) / (V dt)
   (m = 1; the kinetic term is the ideal-gas part Donev's collisional stress leaves out), in
   units of the window's mean kT.
2. Between windows the cell and, affinely, all centres are mapped by F = exp(s E), with the
   symmetric strain (no rotation, Donev 2006, sec. 3.2.4)

       E = alpha / Z * (sigma - P0 I) / max(p, P0),   p = tr(sigma) / d,  Z = p V / (N kT),

   i.e. Donev's linear update Delta Lambda = Delta t W^-1 (sigma - P0 I) Lambda with the cell
   mass chosen per window, W = Z max(p, P0) Delta t / alpha. *Departure*: Donev keeps W fixed
   and deforms the cell during the flight (a quartic contact equation); a fixed W is unstable
   near jamming, where a strain of 1/Z changes the pressure by O(1) (the gaps are ~ D / Z), so
   the step is scaled by 1 / Z: the volume then relaxes by about alpha per window at every
   density. |E| is capped at MAX_STRAIN. *Adaptive mobility*: the 1 / Z scaling suits stiff
   strains but starves a soft one, along which the stress ratio does not change with the strain
   (the anisotropic cage "fabric" of a glass: a 3D LS packing grown with the fixed 1 / Z rule
   kept a mean |sigma - p I| / p near 0.07 from Z = 1e4 to 1e12 while the cell strained by about
   15 gaps per decade of Z, and it was collectively but not strictly jammed). So while the
   particles grow in the shape-only mode (step 4) E is multiplied by a mobility m >= 1: after
   every MOBILITY_BLOCK windows the mean imbalance of the block is compared with the previous
   block's; m is multiplied by MOBILITY_GROW when they point the same way (a persistent
   imbalance: the response is soft) and by MOBILITY_SHRINK otherwise (an overshoot or noise),
   within [1, Z / alpha] (at the top E = (sigma - p I) / p). Otherwise m = 1 (Donev's rule,
   validated by the isobaric dilute-gas and crystal tests): at zero growth there is no growing
   packing to catch up with, and with an applied pressure the volume follows the same strain,
   whose mean an adaptive gain on the stress noise would bias. Block means
   rather than single windows, because one window's shear is mostly noise (20 collisions per
   particle give |sigma - p I| / p ~ 0.1 for a perfectly isotropic mean in 3D, N = 30). With
   the shrink factor below the inverse of the growth factor pure noise drives m to 1. F is the
   exponential (Donev's "more correct" constant strain rate, Eq. 3.2), not his linear I + s E:
   the linear map changes the volume at second order, det(I + E) = 1 + tr E - tr(E^2) / 2 + ...,
   so the noise of the measured shear stress shrank the cell systematically (a dilute gas settled
   1.6e-4 below N kT Z / P0, 4 standard errors). ``adaptive_cell=False`` restores Donev's rule
   with the fixed 1 / Z mobility and the thermostat's window (step 6).
3. s <= 1 is the largest step that leaves every pair at least half its gap along the linear
   path (the first root of |r + s E r| = sigma + gap / 2 over the pairs within reach, and for
   spheres every particle's own images with contact distance SELF_CONTACT times the largest
   diameter: a sphere never collides with its images); after the map the packing is
   checked for overlaps exactly, and the step halved (at most MAX_HALVINGS times, then skipped)
   if round-off made one. Velocities are not changed (the kinetic energy is conserved by a
   deformation).
4. With ``applied_pressure=None`` (Donev's "pressure not fixed") P0 = p, E is traceless and the
   volume is restored exactly after the map (F scaled to det F = 1): only the shape relaxes, and
   the LS growth alone compresses. With a number P0 (units kT / length^d of the packing,
   kT = 1) the volume follows too; with growing particles the reduced pressure P0 V / (N kT)
   then rises with the particle volume, so LS still ends jammed.
5. Windows end at a fixed MD time (the previous window's time per collision times the budget),
   not at a collision, so that no pair is left exactly in contact when the cell deforms (such a
   pair would block any strain that pushes it closer).
6. The cell can follow the growth only if the pressure rises slowly per window: near jamming
   ln Z grows by about 0.6 Gamma w per window of w collisions per particle (measured in 3D), so
   the default window is at most CELL_LAG * alpha / Gamma collisions per particle (ln Z grows by
   about a tenth of alpha per window), besides the thermostat bound of
   :func:`hardpack.md.default_window` (:func:`cell_window`). At the LS rates of a strict-jamming
   run this only shortens the fast stage (Gamma = 0.02: 1 collision per particle instead of
   4.5 in 3D), where the packing acquires its shape. ``adaptive_cell=False`` turns this off,
   with step 2's adaptive mobility.
7. Every window the basis is LLL-reduced (:func:`hardpack.geometry.reduction.lll_reduce`;
   Donev suggests re-reducing, untested by him, sec. 3.2.4) so that a sheared cell keeps short
   lattice vectors.

Growth is uniform (every radius at the same relative rate, d<D>/dt = Gamma, as in
:func:`hardpack.md.compress`) or, with a ``growing`` mask, confined to some particles, each at
dD/dt = Gamma while the others keep their size (Donev 2006, sec. 13.5 grows the large disks of a
labelled crystal at constant pressure); the pair's summed growth rate enters the contact
prediction and the collision law (:func:`hardpack.md._deforming_kernel.pair_sigma`).

Ellipsoids (:class:`EllipsoidDeformingSimulation`) use the same windows, strain rule and cell
map, with the ellipsoid engine's prediction and collision law in the general cell
(:mod:`hardpack.md._ellipsoid_deforming_kernel`, which also explains the stress of non-central
contact forces), the map applied to the centres only, a Perram-Wertheim version of step 3 and a
thermostat that sets the translational and rotational temperatures separately. An ellipsoid
collides with its own periodic images (spin only, derived in that module), so the cell may be
small, down to one particle: every window then needs collisions to measure the stress, so a
window has at least MIN_WINDOW_COLLISIONS collisions, and the next window after one without any
is twice as long (its time cap would otherwise stay at the short length of the last one). With one
particle the translational kinetic tensor v v^T is that of a single velocity (rank one): its
anisotropy, kT / V, is a relative 1 / Z of the pressure and only matters far from jamming.

This is an overdamped, deterministic barostat: it drives the mean stress to P0 I but does not
sample the isobaric ensemble's volume fluctuations. Tests: an ideal-gas check that the mean
volume is N kT Z(phi) / P0, crystals keep their cell, and LS packings of small systems pass the
strict jamming test (``tests/test_md_deforming.py``).
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import unit_ball_volume
from hardpack.geometry.neighbours.grid import MAX_CELLS_PER_PARTICLE, c_strides, cell_counts, perpendicular_widths
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, Packing
from hardpack.geometry.reduction import lll_reduce
from hardpack.geometry.shapes import Ellipsoids
from hardpack.md import _deforming_kernel as dk
from hardpack.md import _ellipsoid_deforming_kernel as edk
from hardpack.md import _ellipsoid_kernel as ek
from hardpack.md import _kernel as mdk
from hardpack.md.compress import CompressResult, StopCriteria, _check_run_options, _stop_reason, default_window
from hardpack.md.ellipsoid_engine import moments_of_inertia, rotational_dof
from hardpack.md.simulation import OverlapError, maxwell_boltzmann

#: default alpha: relative volume relaxation per window (module docstring, step 2)
CELL_STEP = 0.1
#: largest Frobenius norm of one window's strain
MAX_STRAIN = 0.05
#: adaptive cell mobility (module docstring, step 2): windows per block, and the factors by which
#: it grows after two blocks whose mean stress imbalances point the same way and shrinks otherwise
MOBILITY_BLOCK, MOBILITY_GROW, MOBILITY_SHRINK = 10, 2.0, 0.25
#: the default window is at most CELL_LAG * alpha / Gamma collisions per particle (module
#: docstring, step 6)
CELL_LAG = 0.2
#: halvings of a step that overlapped by round-off before the deformation is skipped
MAX_HALVINGS = 8
#: a lattice vector may not become shorter than this many largest diameters (a particle never
#: touches its own image: the bounding spheres need room)
SELF_CONTACT = 1.1
#: bounding-sphere skin in mean radii: start, range and adaptive step (capped by the room the
#: shortest lattice vector leaves); it grows while exits outnumber collisions (dilute fluids) and
#: shrinks when they are below a tenth of them
SHELL_START, SHELL_MIN, SHELL_MAX, SHELL_STEP = 0.3, 0.05, 3.0, 1.5
#: fewest collisions of a window (small cells): a window's stress is measured from its collisions,
#: and one without any reads Z = 1, whose strain would close every gap by half
MIN_WINDOW_COLLISIONS = 10
#: the first window lasts at most this many thermal flight times over a mean diameter per collision
#: asked for (per particle)
FIRST_WINDOW_FLIGHTS = 10.0
#: safety factor of the collision budget of a window that ends at a fixed time
BUDGET_SLACK = 4
#: the ellipsoid image table covers bounding diameters up to this factor above the window start's
#: (and is enlarged by it when a bounding sphere outgrows it)
REACH_SLACK = 1.25

RECORD_FIELDS = ("time", "phi", "Z", "collisions", "kT_mean", "volume", "pressure", "shear",
                 "strain_step", "step_fraction", "mobility", "exits", "wall_time", "growth_rate")


def cell_window(growth_rate: float, d: int, cell_step: float = CELL_STEP) -> float:
    """Default collisions per particle per window of the deforming cell (module docstring,
    step 6): :func:`hardpack.md.default_window`, at most CELL_LAG * cell_step / |growth_rate|
    and at least 1.

    Parameters
    ----------
    growth_rate : float
        Relative growth rate of the radii per unit time (0: none).
    d : int
        Dimension.
    cell_step : float, optional
        Relative cell step alpha per window.

    Returns
    -------
    float
        Collisions per particle per window.
    """
    window = default_window(growth_rate, d)
    if growth_rate == 0:
        return window
    return float(min(window, max(1.0, CELL_LAG * cell_step / abs(growth_rate))))


def shortest_vector(lattice: np.ndarray, heights: np.ndarray | None = None) -> float:
    """Length of the shortest non-zero lattice vector |H n| (exhaustive over the n that can beat
    the shortest basis vector: |n_k| <= l / h_k).

    Parameters
    ----------
    lattice : numpy.ndarray of float, shape (d, d)
        The cell H, lattice vectors as columns.
    heights : numpy.ndarray of float, shape (d,), optional
        The cell's perpendicular widths h_k (:func:`hardpack.geometry.neighbours.grid.perpendicular_widths`),
        if known.

    Returns
    -------
    float
        min over integer n != 0 of |H n|.
    """
    best = float(np.linalg.norm(lattice, axis=0).min())
    if heights is None:
        heights = perpendicular_widths(lattice)
    ranges = [range(-int(best / h), int(best / h) + 1) for h in heights]
    ns = np.array(list(itertools.product(*ranges)), dtype=float)
    ns = ns[np.any(ns != 0, axis=1)]
    if len(ns):
        best = min(best, float(np.linalg.norm(ns @ lattice.T, axis=1).min()))
    return best


def cell_grid(lattice: np.ndarray, width: float, n: int,
              heights: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The single-level cell grid of the deforming-cell kernels' pair searches: cells at least
    ``width`` wide along every lattice direction (at most MAX_CELLS_PER_PARTICLE per particle,
    :func:`hardpack.geometry.neighbours.cell_counts`).

    Parameters
    ----------
    lattice : numpy.ndarray of float, shape (d, d)
        The cell H, lattice vectors as columns.
    width : float
        Smallest cell width (the largest pair reach searched).
    n : int
        Number of particles.
    heights : numpy.ndarray of float, shape (d,), optional
        The cell's perpendicular widths (:func:`hardpack.geometry.neighbours.grid.perpendicular_widths`),
        if known.

    Returns
    -------
    n_cells, strides : numpy.ndarray of int64, shape (1, d)
        Cells per lattice direction and their flat-index strides.
    """
    if heights is None:
        heights = perpendicular_widths(lattice)
    n_cells = cell_counts(heights, [width], [n], MAX_CELLS_PER_PARTICLE)
    return n_cells, c_strides(n_cells)


def check_cell_options(applied_pressure, cell_step) -> None:
    """Refuse a non-positive or non-finite applied pressure or cell step (alpha).

    Parameters
    ----------
    applied_pressure : float or None
        Applied pressure in kT / length^d, or None for a free volume.
    cell_step : float
        Relative cell step alpha, in (0, 1].

    Raises
    ------
    InvalidInputError
        If either is out of range.
    """
    if applied_pressure is not None and (isinstance(applied_pressure, bool) or
                                         not math.isfinite(applied_pressure) or applied_pressure <= 0):
        raise InvalidInputError(f"applied_pressure must be a positive finite number (units kT / "
                                f"length^d) or None for a free volume, got {applied_pressure!r}")
    if isinstance(cell_step, bool) or not (math.isfinite(cell_step) and 0 < cell_step <= 1):
        raise InvalidInputError(f"cell_step (alpha) must be in (0, 1], got {cell_step!r}")


def _check_adaptive_cell(adaptive_cell) -> None:
    if not isinstance(adaptive_cell, (bool, np.bool_)):
        raise InvalidInputError(f"adaptive_cell must be True or False, got {adaptive_cell!r}")


def _check_packing(packing: Packing) -> None:
    if not isinstance(packing, Packing):
        raise InvalidInputError(f"expected a hardpack Packing, got {type(packing).__name__}")
    if packing.shape.kind not in ("sphere", "ellipsoid"):
        raise InvalidInputError(f"the deforming-cell MD handles spheres, ellipsoids and ellipses, not "
                                f"{packing.shape.name}")
    if packing.shape.kind == "ellipsoid" and packing.dim not in (2, 3):
        raise InvalidInputError(f"ellipsoid MD runs in 2D (ellipses) or 3D, not d = {packing.dim}")
    if packing.boundary.kind != "periodic":
        raise InvalidInputError("a deforming cell needs a periodic boundary on every axis; this packing "
                                f"has {packing.boundary}: drop --deforming-cell or use a periodic packing")
    spheres = packing.shape.kind == "sphere"
    if spheres and packing.n_particles < 2:
        raise InvalidInputError("sphere MD in a periodic cell needs at least 2 particles (a sphere never "
                                "collides with its own images)")
    if (packing.shape.kind == "ellipsoid" and packing.n_particles == 1
            and np.ptp(packing.shape.semiaxes) == 0):
        raise InvalidInputError("one ellipsoid with equal semiaxes (a sphere) cannot resolve a contact with "
                                "its own periodic images: use at least 2 particles or unequal semiaxes")
    report = packing.overlap_report(DEFAULT_OVERLAP_TOL)
    if report.n_overlapping:
        raise InvalidInputError(f"the start configuration has overlapping particles ({report}); "
                                "hard-sphere MD needs a non-overlapping start")
    dmax = 2.0 * float(packing.shape.bounding_radii.max())
    if spheres and shortest_vector(packing.lattice) <= SELF_CONTACT * dmax:
        raise InvalidInputError(
            f"the cell is too small: its shortest lattice vector {shortest_vector(packing.lattice):.4g} "
            f"must exceed {SELF_CONTACT} largest diameters ({SELF_CONTACT * dmax:.4g}); use more particles")


def _refuse_window_end(status, lmin: float, diameter: float) -> None:
    """Raise for a window that ended because a particle met its own image or nothing can move."""
    if status == dk.DeformingStatus.SELF_IMAGE:
        raise InvalidInputError(
            f"a particle grew to touch its own periodic image (shortest lattice vector {lmin:.4g}, "
            f"largest bounding diameter {diameter:.4g}): the cell is too small for these particles; "
            "use more particles")
    if status == dk.DeformingStatus.STUCK:
        raise RuntimeError("no event can ever happen: no particle moves and none grows")
    if status == dk.DeformingStatus.STALLED:
        raise RuntimeError("the event loop stalled: a long run of events at one time without a collision "
                           "(an engine failure; please report the packing and seed)")


class DeformingSimulation:
    """State of one deforming-cell run; :meth:`run_window` advances it by one window and then
    deforms the cell (module docstring).

    Parameters
    ----------
    packing : Packing
        Periodic sphere packing without overlaps.
    velocities : numpy.ndarray, shape (N, d)
        Start velocities.
    growth_rate : float
        Gamma: with ``growing`` None every radius grows at the same relative rate with
        d<D>/dt = Gamma (LS growth); with a mask only the masked particles grow, each at
        dD/dt = Gamma, the others keep their size.
    applied_pressure, cell_step, overlap_tol
        As in :func:`compress_deforming`.
    growing : array_like of bool, shape (N,), optional
        The particles that grow (Donev 2006, sec. 13.5 grows the B disks only); None: all, uniformly.
    adaptive_cell : bool, default True
        Adaptive cell mobility while growing in the shape-only mode (module docstring, step 2);
        False: m = 1 always.
    """

    def __init__(self, packing: Packing, velocities: np.ndarray, growth_rate: float,
                 applied_pressure: float | None = None, cell_step: float = CELL_STEP,
                 overlap_tol: float = DEFAULT_OVERLAP_TOL, growing=None, adaptive_cell: bool = True):
        _check_packing(packing)
        check_cell_options(applied_pressure, cell_step)
        _check_adaptive_cell(adaptive_cell)
        if growing is not None:
            growing = np.asarray(growing)
            if growing.dtype != bool or growing.shape != (packing.n_particles,):
                raise InvalidInputError(f"growing must be a boolean mask of the {packing.n_particles} particles, "
                                        f"got dtype {growing.dtype} and shape {growing.shape}")
            if not growing.any():
                raise InvalidInputError("the growing mask selects no particle; use growing=None for uniform "
                                        "growth or growth_rate = 0 for none")
        self.growing = growing
        self.n, self.d = packing.n_particles, packing.dim
        self.H = np.array(packing.lattice, dtype=float)
        self.X = np.array(packing.wrapped().positions, dtype=float)
        self.V = np.ascontiguousarray(velocities, dtype=float).copy()
        self.A = np.array(packing.radii, dtype=float)
        self.T = np.zeros(self.n)
        self._init_run(packing, growth_rate, applied_pressure, cell_step, overlap_tol, adaptive_cell)
        self.ei = np.zeros(self.n, dtype=np.int64)
        self.tv = np.zeros(self.n)

    def _init_run(self, packing, growth_rate, applied_pressure, cell_step, overlap_tol, adaptive_cell) -> None:
        """The run's parameters, counters and event-loop work arrays (spheres and ellipsoids)."""
        n, d = self.n, self.d
        self.species = packing.species
        self.growth_rate = float(growth_rate)
        self.applied_pressure = applied_pressure
        self.cell_step = float(cell_step)
        self.overlap_tol = float(overlap_tol)
        self._measured_cell = None
        self.volume0 = self.volume
        self.capacity = 16
        self.bs = np.zeros((n, d + 1))
        self.nn = np.zeros(n, dtype=np.int64)
        self.mark = np.zeros(n, dtype=np.int8)
        self.cnt = np.zeros(n, dtype=np.int64)
        self.ep = np.zeros(n, dtype=np.int64)
        self.ec = np.zeros(n, dtype=np.int64)
        self.hkey = np.zeros(n)
        self.heap = np.zeros(n, dtype=np.int64)
        self.hpos = np.zeros(n, dtype=np.int64)
        self.kin = np.zeros((d, d))
        self.vir = np.zeros((d, d))
        self.time = 0.0
        self.collisions = 0
        self.windows = 0
        self.wall_time = 0.0
        self.last_duration = 0.0
        self.last_collisions = 0
        self.records: dict[str, list] = {k: [] for k in RECORD_FIELDS}
        self.stress = np.zeros((d, d))
        self.deviatoric: list[np.ndarray] = []
        self.shell = SHELL_START
        self.adaptive_cell = adaptive_cell
        self.mobility = 1.0
        self.block_sum, self.block_count, self.last_block = 0.0, 0, None

    @property
    def volume(self) -> float:
        return self._cell_measures()[1]

    def _inverse(self) -> np.ndarray:
        """H^-1 of the current cell."""
        return self._cell_measures()[0]

    def _cell_measures(self) -> tuple[np.ndarray, float, np.ndarray, dict]:
        """(H^-1, |det H|, perpendicular widths, grids by width) of the current cell, computed
        once per cell: H is replaced by a new array when the cell changes, never changed in place
        (nor are the arrays returned), so the identity of H keys them. A window asked for H^-1 up
        to seven times (10 % of a one-spheroid crystal search, measured), and a sphere window for
        four grids, two of them the same."""
        if self._measured_cell is not self.H:
            self._measured_cell = self.H
            inverse = np.linalg.inv(self.H)
            self._measures = (inverse, abs(float(np.linalg.det(self.H))),
                              1.0 / np.linalg.norm(inverse, axis=1), {})
        return self._measures

    def _search_grid(self, width: float) -> tuple[np.ndarray, np.ndarray]:
        """:func:`cell_grid` of the current cell for cells at least ``width`` wide."""
        _, _, heights, grids = self._cell_measures()
        if width not in grids:
            grids[width] = cell_grid(self.H, width, self.n, heights)
        return grids[width]

    def phi(self) -> float:
        """Volume fraction V_d(1) sum_i a_i^d / V of the current radii in the current cell.

        Returns
        -------
        float
            phi.
        """
        return unit_ball_volume(self.d) * float(np.sum(self.A ** self.d)) / self.volume

    def packing(self) -> Packing:
        """The current configuration, centres wrapped into the current cell."""
        X = self.X.copy()
        dk.wrap_into_cell(X, self.H, self._inverse())
        return Packing(X, self.A.copy(), self.H.copy(), species=self.species, overlap_tol=self.overlap_tol)

    def _reduce_cell(self) -> None:
        reduced, u = lll_reduce(self.H)
        if not np.array_equal(u, np.eye(self.d, dtype=u.dtype)):
            self.H = reduced
        dk.wrap_into_cell(self.X, self.H, self._inverse())

    def relative_rates(self) -> np.ndarray:
        """kappa_i = (da_i/dt) / a_i of the next window (:mod:`hardpack.md._deforming_kernel`): all
        Gamma / (2 <a>) (uniform growth), or Gamma / (2 a_i) for the growing particles and 0 for
        the others."""
        if self.growing is None:
            return np.full(self.n, self.growth_rate / (2.0 * float(self.A.mean())))
        return np.where(self.growing, self.growth_rate / (2.0 * self.A), 0.0)

    def mean_diameter(self) -> float:
        """Mean particle diameter (bounding diameter for ellipsoids)."""
        return 2.0 * float(self.A.mean())

    def run_window(self, coll_target: int, max_time: float = np.inf) -> dict:
        """Run one window of about ``coll_target`` collisions (and at most ``max_time`` MD time)
        in the current cell, measure the stress, rescale velocities (growing runs), deform the
        cell (module docstring, steps 1-7).

        Parameters
        ----------
        coll_target : int
            Collisions asked for: the first window ends after ``coll_target`` collisions (or a time
            cap), the later ones at a time cap (the previous window's time per collision times
            ``coll_target``, at most twice its duration) or after BUDGET_SLACK ``coll_target``
            collisions.
        max_time : float, default inf
            Longest MD time of the window.

        Returns
        -------
        dict
            The window record (keys RECORD_FIELDS), also appended to :attr:`records`: ``time``,
            ``phi``, ``Z`` (inf when no time elapsed), ``collisions`` (total), ``kT_mean``,
            ``volume``, ``pressure`` p = tr(sigma) / d (units of kT_mean / length^d), ``shear``
            |sigma - p I| / p, ``strain_step`` |s E| and ``step_fraction`` s of the cell map,
            ``mobility``, ``exits``, ``wall_time`` and ``growth_rate``.

        Raises
        ------
        OverlapError
            If a pair overlaps by more than the overlap tolerance at the end of the window.
        InvalidInputError
            If a particle grew to touch its own periodic image.
        RuntimeError
            If no event can ever happen or the event loop stalls.
        """
        start = time.perf_counter()
        n, d = self.n, self.d
        self._reduce_cell()
        kappa = self.relative_rates()
        if self.last_duration > 0.0:
            # twice the last window after one without collisions (with a budget of one collision the
            # ratio would keep it at the length of a window that was too short)
            t_cap = 2.0 * self.last_duration
            if self.last_collisions > 0:
                t_cap = min(t_cap, self.last_duration * coll_target / self.last_collisions)
            budget = BUDGET_SLACK * coll_target
        else:
            # the first window ends by FIRST_WINDOW_FLIGHTS thermal flights over a diameter per
            # collision asked for, if not by its collisions (a cell in which no particle can reach
            # another or its own image would otherwise never end it)
            t_cap = FIRST_WINDOW_FLIGHTS * self.mean_diameter() * coll_target / n
            budget = coll_target
        if kappa.min() < 0.0:
            t_cap = min(t_cap, 0.5 / -kappa.min())
        t_cap = min(t_cap, float(max_time))
        duration, colls, exits, ke_int = self._events(kappa, int(budget), float(t_cap))
        self.last_duration, self.last_collisions = duration, colls
        if exits > colls:
            self.shell = min(self.shell * SHELL_STEP, SHELL_MAX)
        elif 10 * exits < colls:
            self.shell = max(self.shell / SHELL_STEP, SHELL_MIN)
        volume = self.volume
        if duration > 0.0 and ke_int > 0.0:
            kt_mean = 2.0 * ke_int / (d * n * duration)
            sigma = (self.kin + self.vir) / (volume * duration * kt_mean)  # units kT_mean / length^d
            z = 1.0 + float(np.trace(self.vir)) / (2.0 * ke_int)
        else:
            kt_mean, sigma, z = np.nan, np.full((d, d), np.nan), np.inf
        self.stress = sigma
        gmin = self._smallest_gap()
        if gmin < -self.overlap_tol:
            raise OverlapError(f"pairs overlap at the end of window {self.windows}: smallest relative gap "
                               f"{gmin:.3e} < -{self.overlap_tol:g}")
        if self.growth_rate != 0.0:
            self._rescale()
        if np.isfinite(z):
            self.update_mobility(sigma, z)
            step, frac = self._deform(sigma, z)
        else:
            step, frac = 0.0, 0.0
        self.time += duration
        self.collisions += colls
        self.windows += 1
        self.wall_time += time.perf_counter() - start
        p = float(np.trace(sigma)) / d
        record = {
            "time": self.time, "phi": self.phi(), "Z": z, "collisions": self.collisions,
            "kT_mean": kt_mean, "volume": self.volume, "pressure": p,
            "shear": float(np.linalg.norm(sigma - p * np.eye(d)) / p) if p > 0 else np.nan,
            "strain_step": step, "step_fraction": frac, "mobility": self.mobility,
            "exits": exits, "wall_time": self.wall_time, "growth_rate": self.growth_rate,
        }
        for k in RECORD_FIELDS:
            self.records[k].append(record[k])
        self.deviatoric.append(sigma / p - np.eye(d) if p > 0 else np.full((d, d), np.nan))
        return record

    def _events(self, kappa: np.ndarray, budget: int, t_cap: float) -> tuple[float, int, int, float]:
        """The window's events in the fixed cell (:func:`hardpack.md._deforming_kernel.run_events`),
        all particles synchronised at its end; fills ``kin`` and ``vir``; returns (duration,
        collisions, bounding-sphere exits, time integral of the kinetic energy)."""
        n = self.n
        Hinv = self._inverse()
        lmin = shortest_vector(self.H, self._cell_measures()[2])
        amax = float(self.A.max())
        skin = np.full(n, min(self.shell * float(self.A.mean()), 0.45 * (lmin - 2.0 * amax)))
        M = dk.image_ranges(self.H, lmin)
        img = dk.image_table(self.H, M)
        cfac = np.linalg.norm(Hinv, axis=1)
        n_cells, cstr = self._search_grid(2.0 * (amax + float(skin.max())))
        saved = (self.X.copy(), self.V.copy())
        while True:
            nb = np.zeros((n, self.capacity), dtype=np.int64)
            acc = np.zeros(2)
            iacc = np.zeros(dk.N_COUNTERS, dtype=np.int64)
            status = dk.run_events(self.X, self.V, self.T, self.A, self.H, Hinv, M, img, cfac, lmin,
                                   n_cells, cstr, kappa, skin, self.bs, nb, self.nn, self.mark, self.cnt, self.ep,
                                   self.ei, self.ec, self.tv, self.hkey, self.heap, self.hpos, self.kin,
                                   self.vir, acc, iacc, budget, t_cap)
            if status == dk.DeformingStatus.OVERFLOW:
                self.X[:], self.V[:] = saved
                self.T[:] = 0.0
                self.capacity *= 2
                continue
            _refuse_window_end(status, lmin, 2 * amax)
            break
        duration = float(acc[0])
        dk.synchronise(self.X, self.V, self.T, self.A, duration, kappa)
        return duration, int(iacc[dk.I_COLL]), int(iacc[dk.I_EXIT]), float(acc[1])

    def _smallest_gap(self) -> float:
        """Smallest relative gap (|r| - sigma) / sigma of the pairs at the window end (a
        particle's own images with sigma its diameter)."""
        amax = float(self.A.max())
        reach = 2.0 * SELF_CONTACT * 2.0 * amax
        _, gmin = dk.strain_limit(self.X, self.A, self.H, self._inverse(), np.zeros((self.d, self.d)),
                                  reach, 2.0 * amax, *self._search_grid(reach))
        return gmin

    def _rescale(self) -> None:
        """Velocities to kT = 1 (growing runs, at every window end)."""
        ke = 0.5 * float(np.sum(self.V * self.V))
        self.V *= math.sqrt(self.d * self.n / (2.0 * ke))

    def imbalance(self, sigma: np.ndarray) -> np.ndarray:
        """(sigma - P0 I) / max(p, P0), symmetric; traceless in the shape-only mode.

        Parameters
        ----------
        sigma : numpy.ndarray of float, shape (d, d)
            Measured stress tensor; p = tr(sigma) / d, and P0 the applied pressure (p in the
            shape-only mode, ``applied_pressure`` None).

        Returns
        -------
        numpy.ndarray of float, shape (d, d)
            The relative stress imbalance.
        """
        d = self.d
        p = float(np.trace(sigma)) / d
        p0 = p if self.applied_pressure is None else float(self.applied_pressure)
        b = (sigma - p0 * np.eye(d)) / max(p, p0)
        b = 0.5 * (b + b.T)
        if self.applied_pressure is None:
            b -= np.trace(b) / d * np.eye(d)
        return b

    def update_mobility(self, sigma: np.ndarray, z: float) -> None:
        """Adapt the mobility from the mean imbalances of the last two blocks of windows while
        the particles grow in the shape-only mode; otherwise m = 1 (module docstring, step 2).

        Parameters
        ----------
        sigma : numpy.ndarray of float, shape (d, d)
            The window's stress tensor.
        z : float
            The window's reduced pressure Z; bounds the mobility by max(Z, 1) / cell_step.
        """
        if not (self.adaptive_cell and self.applied_pressure is None and self.growth_rate > 0):
            self.mobility, self.block_sum, self.block_count, self.last_block = 1.0, 0.0, 0, None
            return
        self.block_sum = self.block_sum + self.imbalance(sigma)
        self.block_count += 1
        if self.block_count < MOBILITY_BLOCK:
            return
        mean = self.block_sum / self.block_count
        if self.last_block is not None:
            if float(np.sum(mean * self.last_block)) > 0.0:
                self.mobility = min(self.mobility * MOBILITY_GROW, max(z, 1.0) / self.cell_step)
            else:
                self.mobility = max(self.mobility * MOBILITY_SHRINK, 1.0)
        self.last_block, self.block_sum, self.block_count = mean, 0.0, 0

    def strain(self, sigma: np.ndarray, z: float) -> np.ndarray:
        """The window's strain E (module docstring, step 2), capped at MAX_STRAIN.

        Parameters
        ----------
        sigma : numpy.ndarray of float, shape (d, d)
            The window's stress tensor.
        z : float
            The window's reduced pressure Z (values below 1 count as 1).

        Returns
        -------
        numpy.ndarray of float, shape (d, d)
            E = cell_step m / max(Z, 1) :meth:`imbalance`, scaled down to Frobenius norm
            MAX_STRAIN if larger.
        """
        e = self.cell_step * self.mobility / max(z, 1.0) * self.imbalance(sigma)
        norm = float(np.linalg.norm(e))
        return e * (MAX_STRAIN / norm) if norm > MAX_STRAIN else e

    def _cell_map(self, s: float, e: np.ndarray, H0: np.ndarray) -> np.ndarray:
        """F = exp(s E) (det F = exp(s tr E) exactly), scaled to keep the start volume in the
        shape-only mode (no drift over many windows)."""
        lam, q = np.linalg.eigh(s * e)
        f = (q * np.exp(lam)) @ q.T
        if self.applied_pressure is None:
            f *= (self.volume0 / abs(np.linalg.det(f @ H0))) ** (1.0 / self.d)
        return f

    def _deform(self, sigma: np.ndarray, z: float) -> tuple[float, float]:
        """Map cell and centres by F = exp(s E) (module docstring, steps 2-4); returns (|s E|, s)."""
        d = self.d
        e = self.strain(sigma, z)
        if not np.any(e):
            return 0.0, 1.0
        Hinv = self._inverse()
        self_sigma = SELF_CONTACT * 2.0 * float(self.A.max())
        reach = 2.0 * max(self_sigma, 2.0 * float(self.A.max()))
        s, _ = dk.strain_limit(self.X, self.A, self.H, Hinv, e, reach, self_sigma, *self._search_grid(reach))
        H0, X0 = self.H.copy(), self.X.copy()
        for _ in range(MAX_HALVINGS + 1):
            if s <= 0.0:
                break
            f = self._cell_map(s, e, H0)
            self.H = f @ H0
            self.X = np.array(X0 @ f.T)
            dk.wrap_into_cell(self.X, self.H, self._inverse())
            _, gmin = dk.strain_limit(self.X, self.A, self.H, self._inverse(),
                                      np.zeros((d, d)), reach, self_sigma, *self._search_grid(reach))
            if gmin >= 0.0:
                return float(s * np.linalg.norm(e)), float(s)
            s *= 0.5
        self.H, self.X = H0, X0
        return 0.0, 0.0


class EllipsoidDeformingSimulation(DeformingSimulation):
    """Deforming-cell run of ellipsoids (3D) or ellipses (2D): the windows of
    :mod:`hardpack.md._ellipsoid_deforming_kernel` (the ellipsoid engine's prediction and collision
    law in a general cell, with the stress tensor), the strain rule of :class:`DeformingSimulation`
    (module docstring, steps 2, 4 to 7), and the cell map applied to the centres only (the
    orientations are not changed by an affine map of the cell: the particles are rigid).

    Step 3 for ellipsoids: the step s starts at 1 and is halved (at most MAX_HALVINGS times, then
    the deformation is skipped) until every pair whose bounding spheres can meet keeps at least
    half its Perram-Wertheim gap, mu - 1 with mu = sqrt(1 + zeta) the scaling factor to tangency
    (Donev 2006, sec. 2.2.2.1; the sphere rule's half gap, since mu = r / (a_i + a_j) for
    spheres), a particle's own images included (they collide with it: any cell without overlaps
    runs, N = 1 too).

    Parameters
    ----------
    packing : Packing
        Periodic ellipsoid or ellipse packing without overlaps.
    velocities : numpy.ndarray, shape (N, d)
        Start velocities.
    angular_velocities : numpy.ndarray, shape (N, 3) in 3D, (N,) in 2D
        Start angular velocities in the lab frame.
    growth_rate : float
        Gamma: every semiaxis grows at the relative rate Gamma / (2 <(prod a)^(1/d)>)
        (:mod:`hardpack.md.ellipsoid`).
    applied_pressure, cell_step, overlap_tol, adaptive_cell
        As for :class:`DeformingSimulation`.
    eps_f : float, optional
        Trace tolerance of the engine.
    """

    def __init__(self, packing: Packing, velocities: np.ndarray, angular_velocities: np.ndarray,
                 growth_rate: float, applied_pressure: float | None = None, cell_step: float = CELL_STEP,
                 overlap_tol: float = DEFAULT_OVERLAP_TOL, adaptive_cell: bool = True, eps_f: float = ek.EPS_F):
        _check_packing(packing)
        if packing.shape.kind != "ellipsoid":
            raise InvalidInputError(f"EllipsoidDeformingSimulation runs ellipsoids, not {packing.shape.name}")
        check_cell_options(applied_pressure, cell_step)
        _check_adaptive_cell(adaptive_cell)
        n, d = packing.n_particles, packing.dim
        shape = packing.shape
        self.growing = None
        self.n, self.d = n, d
        self.H = np.array(packing.lattice, dtype=float)
        cv, ct, cr, cax, cor, cw, cii, width = ek.columns(d)
        self.P = np.zeros((n, width))
        self.P[:, :d] = packing.wrapped().positions
        self.P[:, cv:cv + d] = velocities
        self.P[:, cr] = shape.semiaxes.max(axis=1)
        self.P[:, cax:cax + d] = shape.semiaxes
        self.P[:, cor:cw] = np.asarray(shape.orientations, dtype=float).reshape(n, -1)
        self.P[:, cw:cii] = np.asarray(angular_velocities, dtype=float).reshape(n, -1)
        self.P[:, cii] = 1.0 / moments_of_inertia(shape.semiaxes)
        self.eps_f = float(eps_f)
        self.self_collisions = 0
        self._grid = None
        self._init_run(packing, growth_rate, applied_pressure, cell_step, overlap_tol, adaptive_cell)

    def _column(self, k: int) -> int:
        return ek.columns(self.d)[k]

    def _cell_grid(self, width: float) -> tuple[np.ndarray, np.ndarray]:
        """:func:`cell_grid` of the current cell, made once per cell: the window's events and the
        pair searches after it share it (any grid gives the same lists and pairs; ``width``, the
        first asked for in the cell, only sets how many candidates are tested)."""
        if self._grid is None or not (self._grid[0] is self.H or np.array_equal(self._grid[0], self.H)):
            self._grid = (self.H, *cell_grid(self.H, width, self.n, self._cell_measures()[2]))
        return self._grid[1], self._grid[2]

    def mean_diameter(self) -> float:
        """Mean bounding diameter, twice the mean largest semiaxis.

        Returns
        -------
        float
            The mean bounding diameter.
        """
        return 2.0 * float(self.P[:, self._column(2)].mean())

    @property
    def semiaxes(self) -> np.ndarray:
        cax = self._column(3)
        return self.P[:, cax:cax + self.d]

    @property
    def V(self) -> np.ndarray:
        """Translational velocities (a view of the state rows)."""
        cv = self._column(0)
        return self.P[:, cv:cv + self.d]

    def angular_velocities(self) -> np.ndarray:
        """Lab-frame angular velocities, in the packing's particle order.

        Returns
        -------
        numpy.ndarray of float, shape (N, 3) in 3D, (N,) in 2D
            A copy.
        """
        cw, cii = self._column(5), self._column(6)
        w = self.P[:, cw:cii].copy()
        return w[:, 0] if self.d == 2 else w

    def phi(self) -> float:
        """Volume fraction V_d(1) sum_i prod_k a_ik / V of the current semiaxes in the current cell.

        Returns
        -------
        float
            phi.
        """
        return unit_ball_volume(self.d) * float(np.sum(np.prod(self.semiaxes, axis=1))) / self.volume

    def packing(self) -> Packing:
        """The current configuration, centres wrapped into the current cell (not checked for
        overlaps: callers check it with :meth:`Packing.overlap_report`)."""
        P = self.P.copy()
        dk.wrap_into_cell(P, self.H, self._inverse())
        cor, cw = self._column(4), self._column(5)
        o = P[:, cor:cw]
        shape = Ellipsoids(self.semiaxes.copy(), o[:, 0].copy() if self.d == 2 else o.copy())
        return Packing(P[:, :self.d], lattice=self.H.copy(), species=self.species, shape=shape,
                       overlap_tol=self.overlap_tol, allow_overlap=True)

    def _reduce_cell(self) -> None:
        reduced, u = lll_reduce(self.H)
        if not np.array_equal(u, np.eye(self.d, dtype=u.dtype)):
            self.H = reduced
        dk.wrap_into_cell(self.P, self.H, self._inverse())

    def relative_rates(self) -> np.ndarray:
        """kappa = Gamma / (2 <(prod a)^(1/d)>) for every particle (:mod:`hardpack.md.ellipsoid`)."""
        mean = float(np.mean(np.prod(self.semiaxes, axis=1) ** (1.0 / self.d)))
        return np.full(self.n, self.growth_rate / (2.0 * mean))

    def _events(self, kappa: np.ndarray, budget: int, t_cap: float) -> tuple[float, int, int, float]:
        """The window's events (:func:`hardpack.md._ellipsoid_deforming_kernel.run_events`); the
        kinetic tensor integral K_end t - sum t_c Delta K and the symmetric part of the virial
        tensor into ``kin`` and ``vir``."""
        n, d = self.n, self.d
        Hinv = self._inverse()
        rb = self.P[:, self._column(2)]
        rmax = float(rb.max())
        skin = np.full(n, self.shell * float(rb.mean()))
        # the image table covers bounding spheres grown by REACH_SLACK (the kernel asks for more)
        reach = 2.0 * (rmax + float(skin[0])) * REACH_SLACK
        cfac = np.linalg.norm(Hinv, axis=1)
        n_cells, cstr = self._cell_grid(2.0 * (rmax + float(skin.max())))
        saved = self.P.copy()
        vir, kw = np.zeros((d, d)), np.zeros((d, d))
        while True:
            M = dk.image_ranges(self.H, reach)
            img, cbits = edk.padded_image_table(self.H, M)
            cap = self.capacity
            nb = np.zeros((n, cap), dtype=np.int64)
            acc = np.zeros(edk.N_ACC)
            acc[mdk.A_KE] = 0.5 * float(np.sum(self.V * self.V))
            iacc = np.zeros(edk.N_COUNTERS, dtype=np.int64)
            status = edk.run_events(
                self.P, self.H, Hinv, M, img, cbits, cfac, reach, n_cells, cstr, float(kappa[0]), self.eps_f, skin,
                self.bs, nb, self.nn, self.mark, self.cnt, self.ep, self.ec, self.hkey, self.heap, self.hpos,
                np.empty(cap), np.empty(cap), np.empty(cap, dtype=np.int8), np.empty((cap, ek.PAIR_STATE)),
                vir, kw, acc, iacc, budget, t_cap)
            if status == dk.DeformingStatus.OVERFLOW:
                self.P[:] = saved
                self.capacity *= 2
                continue
            if status == dk.DeformingStatus.SELF_IMAGE:
                if 2.0 * float(self.bs[:, d].max()) >= reach:  # a bounding sphere outgrew the table
                    self.P[:] = saved
                    reach *= REACH_SLACK
                    continue
                raise RuntimeError(
                    f"at window time {acc[mdk.A_T]:.6g} a particle grew into its own periodic image along a "
                    "contact normal on the centre line (r x n = 0), which no rotation can relieve; "
                    "spheres-as-ellipsoids (equal semiaxes) cannot touch their own images: use more "
                    "particles or a larger cell")
            _refuse_window_end(status, 0.0, 2 * rmax)
            break
        self.self_collisions += int(iacc[edk.I_SELF])
        duration = float(acc[mdk.A_T])
        ek.synchronise(self.P, duration, float(kappa[0]))
        v = self.V
        self.kin = v.T @ v * duration - kw
        self.vir = 0.5 * (vir + vir.T)
        return duration, int(iacc[dk.I_COLL]), int(iacc[dk.I_EXIT]), float(acc[mdk.A_KEINT])

    def _pairs(self, scale: float):
        width = 2.0 * scale * float(self.P[:, self._column(2)].max())
        return edk.near_pairs(self.P, self.H, self._inverse(), scale, *self._cell_grid(width))

    def _smallest_gap(self) -> float:
        """Smallest mu - 1 (Perram-Wertheim, relative) of the pairs at the window end."""
        mu, _ = edk.pair_scales(self.P, self.H, *self._pairs(1.0), np.zeros((self.d, self.d)))
        return float(mu.min() - 1.0) if len(mu) else np.inf

    def _rescale(self) -> None:
        """Translational and angular velocities each to kT = 1 (equipartition imposed by the
        thermostat), by two global factors. One factor for both fails for near-spheres: their
        collisions hardly exchange energy with the rotations, so the growth heats the
        translations only and every rescaling moves rotational energy into them; at alpha = 1 the
        translational kT tends to 2 (measured: 2.0000 after 100 windows, 16
        spheres-as-ellipsoids; at alpha = 1.2 it stays near 1.25 during a Gamma = 0.1 growth),
        which slows the growth in units of the thermal speed by sqrt(2). (The fixed-cell
        thermostat, :meth:`hardpack.md.ellipsoid_engine.EllipsoidEngine.rescale_velocities`,
        scales the particles of a window's last collision by one factor: its windows end at a
        collision, these end mostly at their time cap.)"""
        ket, ker, _, _ = ek.totals(self.P)
        cv, cw, cii = self._column(0), self._column(5), self._column(6)
        if ket > 0.0:
            self.P[:, cv:cv + self.d] *= math.sqrt(0.5 * self.d * self.n / ket)
        if ker > 0.0:
            self.P[:, cw:cii] *= math.sqrt(0.5 * rotational_dof(self.d) * self.n / ker)

    def _deform(self, sigma: np.ndarray, z: float) -> tuple[float, float]:
        """Map cell and centres by F = exp(s E) (class docstring); returns (|s E|, s)."""
        d = self.d
        e = self.strain(sigma, z)
        if not np.any(e):
            return 0.0, 1.0
        H0, P0 = self.H.copy(), self.P.copy()
        # every pair (own images included) that F (or its volume correction) can bring within bounding reach
        pairs = self._pairs(math.exp(2.0 * float(np.linalg.norm(e))) * 1.01)
        mu0, rate = edk.pair_scales(P0, H0, *pairs, e)
        # first-order step that keeps half of every approaching pair's zeta (as the sphere rule)
        zeta0 = mu0 * mu0 - 1.0
        closing = rate < 0.0
        s = float(min(1.0, np.min(0.5 * np.maximum(zeta0[closing], 0.0) / -rate[closing], initial=1.0)))
        for _ in range(MAX_HALVINGS + 1):
            if s <= 0.0:
                break
            f = self._cell_map(s, e, H0)
            H1 = f @ H0
            self.P[:, :d] = P0[:, :d] @ f.T
            mu1, _ = edk.pair_scales(self.P, H1, *pairs, e)
            if np.all(np.where(mu0 > 1.0, mu1 - 1.0 >= 0.5 * (mu0 - 1.0), mu1 >= mu0)):
                self.H = H1
                dk.wrap_into_cell(self.P, self.H, self._inverse())
                return float(s * np.linalg.norm(e)), float(s)
            self.P[:] = P0
            s *= 0.5
        self.H, self.P = H0, P0
        return 0.0, 0.0


def mean_shear(deviatoric, fraction: float = 0.25) -> float:
    """Frobenius norm of the mean of sigma / p - I over the last ``fraction`` of the windows
    (NaN without windows): the systematic stress anisotropy, which the noise of single windows
    (the time series' ``shear``) hides.

    Parameters
    ----------
    deviatoric : array_like of float, shape (n_windows, d, d)
        sigma / p - I of every window.
    fraction : float, optional
        Trailing fraction of the windows averaged.

    Returns
    -------
    float
        Frobenius norm of the mean, NaN without windows.
    """
    if not len(deviatoric):
        return float("nan")
    tail = np.asarray(deviatoric, dtype=float)[-max(1, int(round(fraction * len(deviatoric)))):]
    return float(np.linalg.norm(tail.mean(axis=0)))


def compress_deforming(packing: Packing, growth_rate: float, seed: int, stop: StopCriteria | None = None,
                       *, applied_pressure: float | None = None, cell_step: float = CELL_STEP,
                       window: float | None = None, final_growth_rate: float | None = None,
                       switch_pressure: float = 1e3, overlap_tol: float = DEFAULT_OVERLAP_TOL,
                       adaptive_cell: bool = True, eps_f: float = ek.EPS_F, progress=None) -> CompressResult:
    """LS compression (or, at growth rate 0, an isobaric or shape-relaxing run) in a deforming
    periodic cell (module docstring).

    Parameters
    ----------
    packing : Packing
        Periodic packing of spheres (any d), ellipsoids (3D) or ellipses (2D) without overlaps
        (any lattice, sheared or not; ellipsoids run :class:`EllipsoidDeformingSimulation`, with
        uniform growth of the semiaxes, Gamma as in :func:`hardpack.md.ellipsoid.compress_ellipsoids`,
        and velocities and angular velocities at kT = 1); for spheres N >= 2 and the shortest
        lattice vector must exceed SELF_CONTACT largest diameters (ellipsoids collide with their
        own images: any N >= 1 and cell).
    growth_rate : float
        Gamma = (d<D>/dt) / sqrt(kT/m) as in :func:`hardpack.md.compress`; >= 0 (0 needs a
        collision or time limit).
    seed : int
        Non-negative seed of the Maxwell-Boltzmann velocities.
    stop : StopCriteria, optional
        Default: reduced pressure 1e12. ``target_phi`` is refused (phi also changes with the cell).
    applied_pressure : float, optional
        P0 in units kT / length^d of the packing (kT = 1); None (default) relaxes only the shape
        at the current volume (P0 = tr(sigma) / d).
    cell_step : float, default CELL_STEP
        alpha of the strain rule, in (0, 1].
    window : float, optional
        Collisions per particle per window (one deformation per window); default
        :func:`cell_window` of the current stage's rate (:func:`hardpack.md.default_window`
        with ``adaptive_cell=False``).
    final_growth_rate, switch_pressure : float
        Two-stage protocol as in :func:`hardpack.md.compress`.
    overlap_tol : float
        Relative overlap tolerance checked at every window end.
    adaptive_cell : bool, default True
        The adaptive cell mobility while growing in the shape-only mode and the default window
        :func:`cell_window` (module docstring, steps 2 and 6); False: Donev's rule with the fixed
        1 / Z mobility and the window :func:`hardpack.md.default_window`.
    eps_f : float
        Trace tolerance of the ellipsoid engine (:data:`hardpack.md._ellipsoid_kernel.EPS_F`;
        ellipsoids only).
    progress : callable, optional
        Receives each window's record.

    Returns
    -------
    CompressResult
        The final packing (its lattice is the deformed cell), velocities, the per-window
        time series (with ``volume``, ``pressure``, ``shear`` = |sigma - p I| / p and
        ``strain_step``, ``mobility``, the tensor ``deviatoric``) and stats (protocol
        "lubachevsky_stillinger_deforming_cell", ``applied_pressure``, ``cell_step``, the
        ``adaptive_cell`` switch, the mobility and window parameters, final ``shear``,
        ``shear_mean`` (:func:`mean_shear`), volume change).

    Raises
    ------
    InvalidInputError
        For a packing that is not periodic spheres, too small a cell, overlaps, bad rates,
        seed, window, applied pressure, cell step or adaptive_cell, or a target phi.
    OverlapError
        If pairs overlap beyond ``overlap_tol`` at a window end (an engine failure).
    """
    _check_packing(packing)
    check_cell_options(applied_pressure, cell_step)
    _check_adaptive_cell(adaptive_cell)
    if isinstance(growth_rate, bool) or not isinstance(growth_rate, (int, float, np.floating, np.integer)) \
            or not math.isfinite(growth_rate) or growth_rate < 0:
        raise InvalidInputError(f"growth_rate must be a finite number >= 0 with a deforming cell, got {growth_rate!r}")
    if stop is not None and stop.target_phi is not None:
        raise InvalidInputError("target_phi is not supported with a deforming cell (phi changes with the "
                                "cell too): stop at a pressure, a collision count or a wall time")
    stop = _check_run_options(packing, growth_rate, seed, stop, final_growth_rate, switch_pressure, window)

    def stage_window(rate: float) -> float:
        if window is not None:
            return float(window)
        return cell_window(rate, packing.dim, cell_step) if adaptive_cell else default_window(rate, packing.dim)

    if packing.shape.kind == "ellipsoid":
        from hardpack.md.ellipsoid import random_angular_velocities

        seeds = np.random.SeedSequence(seed).spawn(2)
        n, d = packing.n_particles, packing.dim
        sim = EllipsoidDeformingSimulation(
            packing, maxwell_boltzmann(n, d, seeds[0]),
            random_angular_velocities(n, d, moments_of_inertia(packing.shape.semiaxes), seeds[1]),
            growth_rate, applied_pressure, cell_step, overlap_tol, adaptive_cell=adaptive_cell, eps_f=eps_f)
        sim._rescale()
    else:
        sim = DeformingSimulation(packing, maxwell_boltzmann(packing.n_particles, packing.dim, seed),
                                  growth_rate, applied_pressure, cell_step, overlap_tol, adaptive_cell=adaptive_cell)
    started = time.perf_counter()
    while (reason := _stop_reason(stop, sim, started)) is None:
        budget = max(MIN_WINDOW_COLLISIONS, round(stage_window(sim.growth_rate) * sim.n))
        if stop.max_collisions is not None:
            budget = min(budget, int(stop.max_collisions) - sim.collisions)
        record = sim.run_window(budget)
        if final_growth_rate is not None and sim.growth_rate != final_growth_rate \
                and record["Z"] >= switch_pressure:
            sim.growth_rate = float(final_growth_rate)
        if progress is not None:
            progress(record)
    final = sim.packing()
    report = final.overlap_report(overlap_tol)
    rec = sim.records
    stats = {
        "protocol": "lubachevsky_stillinger_deforming_cell", "growth_rate": float(growth_rate),
        "seed": int(seed), "stop_reason": reason, "Z": float(rec["Z"][-1]) if rec["Z"] else float("nan"),
        "phi": float(final.phi), "collisions": int(sim.collisions), "windows": int(sim.windows),
        "phi_J_est": float(final.phi / (1.0 - sim.d / rec["Z"][-1])) if rec["Z"] and rec["Z"][-1] > sim.d
        else float("nan"),
        "md_time": float(sim.time), "wall_time": float(sim.wall_time),
        "window_collisions_per_particle": stage_window(growth_rate), "overlap_tol": overlap_tol,
        "n_overlapping": int(report.n_overlapping),
        "overlap_check": "passed" if report.n_overlapping == 0 else "failed",
        "applied_pressure": "none (shape only, P0 = tr(sigma)/d)" if applied_pressure is None
        else float(applied_pressure),
        "cell_step": float(cell_step),
        "shear": float(rec["shear"][-1]) if rec["shear"] else float("nan"),
        "shear_mean": mean_shear(sim.deviatoric),
        "adaptive_cell": bool(adaptive_cell), "mobility_block": MOBILITY_BLOCK,
        "mobility_grow": MOBILITY_GROW, "mobility_shrink": MOBILITY_SHRINK,
        "cell_lag": CELL_LAG, "final_mobility": float(sim.mobility),
        "volume_ratio": sim.volume / sim.volume0, "mass": 1.0, "kT": 1.0,
        "shape_kind": packing.shape.kind,
    }
    if packing.shape.kind == "ellipsoid":
        stats.update(eps_f=float(sim.eps_f), max_overlap=float(report.overlap),
                     moment_of_inertia="spherically symmetric: (2/15)(a^2+b^2+c^2) in 3D, (a^2+b^2)/4 in 2D")
    if final_growth_rate is not None:
        stats.update({"final_growth_rate": float(final_growth_rate), "switch_pressure": float(switch_pressure)})
    units = {k: k for k in RECORD_FIELDS}
    units.update(volume="cell volume |det H| at the window end",
                 pressure="tr(sigma)/d over the window, units kT_mean / length^d",
                 shear="|sigma - p I| / p over the window (Frobenius)",
                 strain_step="Frobenius norm of the strain applied after the window",
                 mobility="adaptive cell mobility m used after the window (module docstring, step 2)",
                 step_fraction="s: the fraction of the strain rule's step that kept every gap >= half")
    data = {k: ("window", np.asarray(rec[k], dtype=float), {"description": units[k]}) for k in RECORD_FIELDS}
    data["deviatoric"] = (("window", "row", "col"), np.asarray(sim.deviatoric, dtype=float).reshape(-1, sim.d, sim.d),
                          {"description": "sigma / p - I over the window (its mean is the anisotropy; one "
                                          "window's is mostly noise)"})
    ts = xr.Dataset(data, coords={"window": np.arange(len(rec["time"]))})
    ts.attrs.update({"hardpack_kind": "md_timeseries", "N": sim.n, "d": sim.d, "seed": int(seed),
                     "growth_rate": float(growth_rate), "stop_reason": reason})
    v = sim.V.copy()
    return CompressResult(final, v, ts, stats)
