"""Lubachevsky-Stillinger (LS) compression: event-driven MD with growing spheres.

Protocol (Donev 2006, dissertation secs. 1.1-1.2; Ogarko 2014, secs. 3.1.3 and 3.3.1): start from a
non-overlapping packing, draw Maxwell-Boltzmann velocities (kT = m = 1), grow every radius in
proportion to its size while running collision-driven MD, rescale velocities to kT = 1 at every
synchronisation point, and stop at a reduced pressure (default 1e12), a volume fraction, a number
of collisions or a wall-clock limit.

**Growth rate.** ONE dimensionless rate Gamma = (d<D>/dt) / sqrt(kT/m): the growth speed of the
mean diameter in units of the thermal speed (kT = m = 1). Radii grow linearly in time,
a_i(t) = a_i(0) (1 + 2 Gamma t / <D>(0)), so every particle keeps its size relative to the others.
Conversions to the seeds' conventions:

- Skoge/Donev ``growthrate`` g (the C++ "spheres" code of Skoge et al. 2006): a RADIUS rate
  dr/dt = g with velocities rescaled to <v^2> = 1, i.e. kT/m = 1/d:  Gamma = 2 sqrt(d) g.
- Donev's text gamma (Donev 2006, sec. 3.3.1, radius rate in units of sqrt(kT/m)): Gamma = 2 gamma;
  sec. 1.2.2 uses a diameter rate, for which Gamma = gamma.
- Ogarko Gamma_O (Eq. 3.32: da_i/dt = Gamma_O (a_i/a_max) v0, v0 = sqrt(2E/(3M)) = sqrt(kT/m)
  in 3D): Gamma = 2 Gamma_O <a>/a_max (= 2 Gamma_O for monodisperse spheres).

**Two-stage protocol** (``final_growth_rate``): fast growth straight to Z = 1e12 leaves the
packing out of equilibrium near jamming, and the final packings are hypostatic and not even
locally jammed (3D, N = 500, Gamma = 0.02: 1362 contacts within 1e-6 against ~1470 for an
isostatic backbone). Growing at ``growth_rate`` until the window pressure reaches
``switch_pressure`` and then at the much smaller ``final_growth_rate`` lets the contact network
relax while the pressure diverges. The slow stage dominates the cost, about
c N ln(Z_max / Z_switch) / Gamma_f collisions with c ~ 1.7 in 3D and ~1.0 in 2D (the
collisions per particle per e-fold of Z are ~ 1 / Gamma_f). Measured (N = 500, Gamma = 0.02,
Z_switch = 1e3, Z_max = 1e12, 3 seeds each, :func:`hardpack.jamming.verify`):

- 3D monodisperse: Gamma_f = 1e-3: hypostatic by 5-6 contacts, never collectively jammed
  (1.8e7 collisions); 3e-4: isostatic within +-1, collectively jammed in 2 of 3 (5.8e7);
  2e-4: isostatic (Z = 5.992 without rattlers, 1.4-3.0 % rattlers) in 3 of 3 and collectively
  jammed in 3 of 3 when the ideal test ignores motions below 1e-3 D (its default threshold,
  1.3e-6 D, flags 2 of them for motions of 2e-6 and 6e-6 D) (8.8e7 collisions, ~60 s CPU);
  1e-4: isostatic and collectively jammed in 3 of 3 with the default test, 2.2-3.4 % rattlers
  (1.7e8 collisions, ~120 s CPU).
- 2D equimolar binary disks (ratio 1.4): 1e-3: 0 of 3; 3e-4: 2 of 3; 2e-4 and 1e-4: 3 of 3
  collectively jammed and isostatic, 5-8 % rattlers (5.6e7 and 1.1e8 collisions).
- Switching at Z = 1e2 or 1e4 instead of 1e3 changes nothing systematic (only the cost, by
  ln(Z_max / Z_switch)); going back to fast growth after the slow stage (slow only up to Z = 1e6)
  destroys the isostatic network again: the slow rate is needed all the way to Z_max.

Recommended: ``growth_rate=0.02, switch_pressure=1e3, final_growth_rate=2e-4`` (1e-4 where the
verifier's default thresholds must pass).

**Checks of the end state.** A run asked for a target phi without a pressure cap stops with
an :class:`InvalidInputError` when its reduced pressure passes ``JAMMED_PRESSURE`` while the
jamming-density estimate is still below the target: the packing jammed at this growth rate short
of the target (the LS jamming density rises as the growth rate falls). A run stopped at
``max_pressure`` claims a jammed packing; :func:`jamming_backbone` checks the claim (stats
``backbone_volume_fraction`` and ``jamming_check``, and a warning when it fails).

**Pressure.** Per window Z = pV/(NkT) = 1 + sum_coll r_ij . J_ij / (d N kT dt) with kT the
window's time-averaged kinetic temperature (derived here from the collisional stress of Donev 2006,
sec. 3.2.4.2, plus the ideal-gas term: Z = 1 + virial / (2 * integral of KE dt)); the running
jamming-density estimate is phi_J_est = phi / (1 - d/Z), the free-volume form
p = d / (1 - phi/phi_J) (Donev 2006, Eqs. 1.1-1.2).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError, check_seed
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, Packing
from hardpack.io import checkpoint as ckpt
from hardpack.io import interrupt, packing_to_dataset, write_dataset
from hardpack.md.simulation import (
    Simulation,
    check_packing,
    maxwell_boltzmann,
)

log = logging.getLogger("hardpack.md")

#: default heating per window: collisions per particle ~ HEATING * d / Gamma (see default_window)
HEATING = 0.03
MAX_WINDOW = 20.0
#: reduced pressure at which a run that must reach a target phi without a pressure cap counts as
#: jammed short of it (contact gaps ~ D / Z = 1e-9 D: the particles cannot rearrange any more)
JAMMED_PRESSURE = 1e9
#: end-state check of runs stopped at max_pressure (:func:`jamming_backbone`): relative contact
#: gap and the smallest share of the particle volume that must sit in the d + 1 contact backbone
BACKBONE_GAP = 1e-2
MIN_BACKBONE_VOLUME = 0.5


@dataclass(frozen=True)
class StopCriteria:
    """Composable stop criteria, checked at every synchronisation point; the first met stops.

    max_pressure: reduced pressure Z (growing runs only); target_phi: volume fraction (reached
    exactly: the last window ends when phi hits it); max_collisions: total collisions;
    max_wall_time: seconds of wall-clock time in this invocation. None disables a criterion.

    Parameters
    ----------
    max_pressure : float or None, default 1e12
        Stop when the window's reduced pressure Z = pV/(NkT) reaches it (growing runs only);
        finite and > 1.
    target_phi : float or None, default None
        Stop when the volume fraction reaches it exactly, in (0, 1); above the start phi for a
        positive growth rate, below it for a negative one (then required).
    max_collisions : int or None, default None
        Stop after this many collisions in all (a positive integer).
    max_wall_time : float or None, default None
        Stop after this many wall-clock seconds in this invocation (> 0).

    Notes
    -----
    The values are checked against the growth rate and start phi by :meth:`check`, which
    :func:`compress` calls and which raises InvalidInputError for impossible or never-ending
    combinations.
    """

    max_pressure: float | None = 1e12
    target_phi: float | None = None
    max_collisions: int | None = None
    max_wall_time: float | None = None

    def check(self, growth_rate: float, phi: float) -> None:
        """Refuse impossible or never-ending combinations for this growth rate and start phi.

        Parameters
        ----------
        growth_rate : float
            The run's growth rate Gamma (> 0 grows, < 0 shrinks, 0 fixed size).
        phi : float
            Volume fraction at the start.

        Raises
        ------
        InvalidInputError
            If a criterion is out of range (max_pressure not finite and > 1, target_phi outside
            (0, 1), max_collisions not a positive integer, max_wall_time not positive); if growing
            with target_phi not above phi or with no criterion at all; if shrinking without a
            target_phi below phi; or at growth rate 0 without max_collisions or max_wall_time.
        """
        if self.max_pressure is not None and not (math.isfinite(self.max_pressure) and self.max_pressure > 1):
            raise InvalidInputError(f"max_pressure must be a finite number > 1, got {self.max_pressure!r}")
        if self.target_phi is not None and not 0 < self.target_phi < 1:
            raise InvalidInputError(f"target_phi must be in (0, 1), got {self.target_phi!r}")
        if self.max_collisions is not None and (int(self.max_collisions) != self.max_collisions
                                                or self.max_collisions < 1):
            raise InvalidInputError(f"max_collisions must be a positive integer, got {self.max_collisions!r}")
        if self.max_wall_time is not None and not self.max_wall_time > 0:
            raise InvalidInputError(f"max_wall_time must be positive seconds, got {self.max_wall_time!r}")
        bounded = self.max_collisions is not None or self.max_wall_time is not None
        if growth_rate > 0:
            if self.target_phi is not None and self.target_phi <= phi:
                raise InvalidInputError(
                    f"target_phi {self.target_phi} is not above the start phi {phi:.6g}; growing "
                    "particles can only increase phi (use a negative growth rate to shrink)"
                )
            if self.max_pressure is None and self.target_phi is None and not bounded:
                raise InvalidInputError("no stop criterion: set max_pressure, target_phi, "
                                        "max_collisions or max_wall_time")
        elif growth_rate < 0:
            if self.target_phi is None or self.target_phi >= phi:
                raise InvalidInputError(
                    f"a negative growth rate shrinks the particles: it needs target_phi below the "
                    f"start phi {phi:.6g} (otherwise the radii would shrink to zero)"
                )
        elif not bounded:
            raise InvalidInputError(
                "growth_rate = 0 never raises the pressure or phi: set max_collisions or "
                "max_wall_time (or use hardpack.md.equilibrate)"
            )


@dataclass
class CompressResult:
    """Final packing, final velocities (m = 1, kT = 1), per-window time series, run stats and
    optionally the MD contact forces.

    Attributes
    ----------
    packing : Packing
        The final packing.
    velocities : numpy.ndarray, shape (N, d)
        Final velocities (m = 1, kT = 1 after the last rescaling).
    timeseries : xarray.Dataset
        One row per synchronisation window along ``window`` (``hardpack_kind`` =
        "md_timeseries"): ``time``, ``phi``, ``Z``, ``phi_J_est``, ``collisions``, ``kT``,
        ``kT_mean``, event counts, ``max_overlap``, ``shell``, ``neighbours``, ``wall_time``,
        ``growth_rate``.
    stats : dict
        Protocol, ``growth_rate``, ``seed``, ``stop_reason``, final ``Z``, ``phi``,
        ``phi_J_est``, collision / event / window counts, times, overlap check, and for a
        two-stage run the final stage's rate and collisions; for a run stopped at max_pressure
        also ``backbone_volume_fraction`` and ``jamming_check``.
    contacts : xarray.Dataset or None
        The time-averaged MD contact forces (``md_contact_*`` variables) when asked for.
    """

    packing: Packing
    velocities: np.ndarray
    timeseries: xr.Dataset
    stats: dict = field(default_factory=dict)
    #: MD contact forces (``compress(..., contact_forces=True)``): a Dataset of md_contact_*
    #: variables (:func:`hardpack.md.contacts.ContactAccumulator.result`), else None
    contacts: xr.Dataset | None = None

    def to_dataset(self) -> xr.Dataset:
        """The final packing as a Dataset, with the stats as attributes and the MD contact forces
        as extra variables when they were accumulated.

        Returns
        -------
        xarray.Dataset
            The packing layout of :func:`hardpack.io.packing_to_dataset` (``hardpack_kind`` =
            "packing"), ``stats`` in its attributes, and the ``md_contact_*`` variables of
            :attr:`contacts` if any. The time series is :attr:`timeseries`.
        """
        extra = None if self.contacts is None else dict(self.contacts.data_vars)
        return packing_to_dataset(self.packing, self.stats, extra)

    def save(self, packing_path, timeseries_path=None, config=None):
        """Write :meth:`to_dataset` and optionally the time series, atomically with provenance
        (the seed of ``stats`` included).

        Parameters
        ----------
        packing_path : str or os.PathLike
            netCDF file of the final packing.
        timeseries_path : str or os.PathLike, optional
            netCDF file of :attr:`timeseries`; not written if None.
        config : object, optional
            Run parameters recorded as provenance (:func:`hardpack.io.write_dataset`).
        """
        write_dataset(self.to_dataset(), packing_path, config=config, seed=self.stats.get("seed"))
        if timeseries_path is not None:
            write_dataset(self.timeseries, timeseries_path, config=config, seed=self.stats.get("seed"))


def default_window(growth_rate: float, d: int) -> float:
    """Collisions per particle per synchronisation window.

    With equal masses each collision adds g |v_n| of kinetic energy, so the relative heating per
    collision per particle is about 2 Gamma sqrt(pi) / d (mean |v_n| of colliding pairs sqrt(pi kT)
    and g / sigma = Gamma / <D>). HEATING * d / Gamma collisions per particle keep the heating
    between rescalings near 10 %, capped at MAX_WINDOW (Skoge-Donev use ~20 events per particle).

    Parameters
    ----------
    growth_rate : float
        The dimensionless growth rate Gamma (module docstring); its sign is ignored.
    d : int
        The dimension.

    Returns
    -------
    float
        HEATING * d / |Gamma| clipped to [1, MAX_WINDOW]; MAX_WINDOW for Gamma = 0.
    """
    if growth_rate == 0:
        return MAX_WINDOW
    return float(np.clip(HEATING * d / abs(growth_rate), 1.0, MAX_WINDOW))


def timeseries_dataset(sim: Simulation, attrs: dict) -> xr.Dataset:
    """The window records as an xarray Dataset with dimension ``window``.

    Parameters
    ----------
    sim : Simulation
        The run whose ``records`` (one entry per window for each of ``sim.fields``) are converted.
    attrs : dict
        Attributes of the dataset (run statistics).

    Returns
    -------
    xarray.Dataset
        One variable per recorded field on dimension ``window``, each with a description; attribute
        ``hardpack_kind = "md_timeseries"``.
    """
    units = {
        "time": "MD time (m = kT = 1, lengths of the packing)", "phi": "volume fraction at the end",
        "Z": "reduced pressure pV/(NkT) over the window", "phi_J_est": "phi / (1 - d/Z)",
        "collisions": "cumulative collisions", "kT": "kinetic temperature at the end, before rescaling",
        "kT_mean": "time-averaged kinetic temperature of the window", "events": "cumulative events",
        "stale": "stale (invalidated) events in the window", "exits": "neighbourhood exits in the window",
        "grazing": "predicted collisions skipped because v_n >= 0 (round-off grazes)",
        "max_overlap": "largest relative overlap 1 - r/(a_i + a_j) at the end",
        "shell": "bounding-sphere shell / radius used", "neighbours": "mean neighbour-list length",
        "wall_time": "cumulative wall-clock seconds",
        "growth_rate": "Gamma = (d<D>/dt)/sqrt(kT/m) used in the window",
        "Z_wall": "reduced pressure on the walls p_w V/(N kT) over the window (hardpack.md.simulation)",
        "wall_collisions": "reflections at hard walls in the window",
    }
    data = {k: ("window", np.asarray(sim.records[k], dtype=float), {"description": units[k]})
            for k in sim.fields}
    ds = xr.Dataset(data, coords={"window": np.arange(len(sim.records["time"]))})
    ds.attrs.update({"hardpack_kind": "md_timeseries", **attrs})
    return ds


def stop_pressure(records: dict) -> float:
    """The reduced pressure that ends a compression at ``max_pressure``: the collision-virial Z of
    the last window, or, in a window without pair collisions (Z = 1 exactly: a particle alone in
    a container, or particles held apart only by hard walls), the pressure on the walls Z_wall,
    which diverges when such a packing jams.

    Parameters
    ----------
    records : dict of list of float
        The per-window records of a run (keys "Z" and, with hard walls, "Z_wall").

    Returns
    -------
    float
        The reduced pressure Z = pV/(NkT) compared with ``max_pressure``.
    """
    z = records["Z"][-1]
    if z == 1.0 and records.get("Z_wall"):
        z_wall = records["Z_wall"][-1]
        if math.isfinite(z_wall):
            return z_wall
    return z


def _stop_reason(stop: StopCriteria, sim: Simulation, started: float) -> str | None:
    rec = sim.records
    if rec["Z"]:
        if sim.growth_rate > 0 and stop.max_pressure is not None and stop_pressure(rec) >= stop.max_pressure:
            return "max_pressure"
        phi = rec["phi"][-1]
        if stop.target_phi is not None:
            tol = 1e-12 * stop.target_phi
            if (sim.growth_rate > 0 and phi >= stop.target_phi - tol) or (
                    sim.growth_rate < 0 and phi <= stop.target_phi + tol):
                return "target_phi"
    if stop.max_collisions is not None and sim.collisions >= stop.max_collisions:
        return "max_collisions"
    if stop.max_wall_time is not None and time.perf_counter() - started >= stop.max_wall_time:
        return "max_wall_time"
    return None


def _check_final_stage(growth_rate: float, final_growth_rate, switch_pressure, stop: StopCriteria) -> None:
    if final_growth_rate is None:
        return
    if isinstance(final_growth_rate, bool) or not isinstance(final_growth_rate, (int, float, np.floating, np.integer)) \
            or not (math.isfinite(final_growth_rate) and final_growth_rate > 0):
        raise InvalidInputError(f"final_growth_rate must be a finite positive number, got {final_growth_rate!r}")
    if not growth_rate > 0:
        raise InvalidInputError("a final (slow) growth stage needs a positive growth_rate for the first stage")
    if isinstance(switch_pressure, bool) or not isinstance(switch_pressure, (int, float, np.floating, np.integer)) \
            or not (math.isfinite(switch_pressure) and switch_pressure > 1):
        raise InvalidInputError(f"switch_pressure must be a finite number > 1, got {switch_pressure!r}")
    if stop.max_pressure is not None and switch_pressure >= stop.max_pressure:
        raise InvalidInputError(
            f"switch_pressure {switch_pressure:g} is not below max_pressure {stop.max_pressure:g}: the "
            "final growth stage would never run (lower switch_pressure or drop final_growth_rate)"
        )


def _check_run_options(packing: Packing, growth_rate, seed, stop: StopCriteria | None, final_growth_rate,
                       switch_pressure, window) -> StopCriteria:
    """Refuse invalid options of a compression run (sphere or ellipsoid engine): the growth rate,
    the seed, the stop criteria (the default ones for None, returned), the two-stage parameters and
    the window."""
    if isinstance(growth_rate, bool) or not isinstance(growth_rate, (int, float, np.floating, np.integer)) \
            or not math.isfinite(growth_rate):
        raise InvalidInputError(f"growth_rate must be a finite number, got {growth_rate!r}")
    check_seed(seed)
    stop = StopCriteria() if stop is None else stop
    stop.check(float(growth_rate), packing.phi)
    _check_final_stage(float(growth_rate), final_growth_rate, switch_pressure, stop)
    if window is not None and not (math.isfinite(window) and window > 0):
        raise InvalidInputError(f"window must be a positive number of collisions per particle, got {window!r}")
    return stop


def jamming_backbone(packing: Packing, gap: float = BACKBONE_GAP) -> float:
    """Share of the particle volume in the packing's d + 1 contact backbone.

    Contacts are pairs with relative gap ``|r_ij| / (a_i + a_j) - 1 <= gap`` and, with hard walls,
    particle-wall contacts with relative gap h / a_i - 1 <= gap; particles with fewer
    than d + 1 contacts (which cannot be locally jammed: d vectors do not positively span R^d,
    Donev 2006, ch. 4, local jamming) are removed repeatedly together with their contacts, and the volume of
    the particles left is returned as a fraction of the total. Near a jammed state at reduced
    pressure Z the contact gaps are ~ D / Z (free-volume theory, Donev 2006, Eqs. 1.1-1.2), far
    below ``gap = 1e-2`` once Z > 1e3, while only rattlers (a few percent of the particles, mostly
    small ones) lack d + 1 contacts; weighting by volume keeps many small rattlers of a wide size
    distribution from counting against a jammed backbone of large particles. A value far below 1
    (every particle a rattler after a growth much faster than the thermal speed; a chain of hard
    rods in d = 1, which jam only at phi = 1) means the end state is not jammed, whatever the
    pressure measured in the last window.

    Parameters
    ----------
    packing : Packing
        A sphere packing.
    gap : float, optional
        Largest relative gap of a contact.

    Returns
    -------
    float
        Volume fraction of the particles in the backbone, in [0, 1].

    Raises
    ------
    InvalidInputError
        For non-spherical particles.
    """
    from hardpack.geometry.balls import ball_volume
    from hardpack.geometry.neighbours import pairs_within

    if packing.shape.kind != "sphere":
        raise InvalidInputError(f"{packing.shape.name} are not supported by the jamming backbone of an LS "
                                "compression yet; it handles hard spheres only")
    pairs = pairs_within(packing, rel_gap=gap)
    i, j = np.asarray(pairs.i), np.asarray(pairs.j)
    n, d = packing.n_particles, packing.dim
    walls = packing.boundary.wall_contacts(packing.positions, packing.radii, packing.lattice, gap)
    on_wall = np.bincount(walls.particle, minlength=n)
    if packing.boundary.kind == "spherical_container":
        # a sphere within the gap of the wall on its FAR side too (R + |x - c| <= a (1 + gap))
        # touches it all round: it cannot move in any direction, as with d + 1 contacts
        far = packing.boundary.radius + np.linalg.norm(packing.positions - np.array(packing.boundary.centre), axis=1)
        on_wall[far <= packing.radii * (1.0 + gap)] = d + 1
    alive = np.ones(n, dtype=bool)
    while True:
        keep = alive[i] & alive[j]
        count = np.bincount(i[keep], minlength=n) + np.bincount(j[keep], minlength=n) + on_wall
        drop = alive & (count < d + 1)
        if not drop.any():
            break
        alive &= ~drop
    volume = ball_volume(packing.radii, d)
    return float(volume[alive].sum() / volume.sum())


def _end_state_check(final: Packing, stats: dict) -> None:
    """Record (and warn about) a run stopped at max_pressure whose end state is not jammed."""
    share = jamming_backbone(final)
    passed = share >= MIN_BACKBONE_VOLUME
    stats.update(backbone_volume_fraction=share, jamming_check="passed" if passed else "far_from_jammed")
    if passed:
        return
    d = final.dim
    why = ("hard rods (d = 1) jam only at phi = 1: compress to a --target-phi instead"
           if d == 1 else
           f"the growth rate {stats['growth_rate']:g} is probably too fast for the particles to "
           "rearrange (the LS protocol needs growth well below the thermal speed, e.g. 0.02, with "
           "a slow final stage)")
    log.warning(
        "the end state is far from jammed although the reduced pressure reached %.3g: only %.1f %% "
        "of the particle volume has %d or more contacts within a relative gap of %g (a jammed "
        "packing has nearly all of it); %s", stats["Z"], 100 * share, d + 1, BACKBONE_GAP, why)


def _jammed_short(stop: StopCriteria, record: dict, growth_rate: float) -> None:
    """Refuse to go on when a run that must reach ``stop.target_phi`` jammed below it."""
    if stop.target_phi is None or stop.max_pressure is not None or growth_rate <= 0 \
            or record["Z"] < JAMMED_PRESSURE:
        return
    phi_j = record["phi_J_est"] if math.isfinite(record["phi_J_est"]) else record["phi"]
    if phi_j >= stop.target_phi:
        return
    raise InvalidInputError(
        f"target phi {stop.target_phi:g} is above the jamming density reached: at growth rate "
        f"{growth_rate:g} the packing jammed at phi = {phi_j:.6f} (reduced pressure {record['Z']:.3g}). "
        "Choose a target phi below it, or compress more slowly (a smaller growth rate: "
        "--growth-rate of compress, --prep-rate of eos), which jams denser"
    )


def run_windows(sim, stop: StopCriteria, stage_window, checkpoint, fingerprint: str, *, final_growth_rate=None,
                switch_pressure: float = 1e3, progress=None, progress_interval: float = 10.0,
                checkpoint_interval: float = 300.0, label: str = "") -> str:
    """Run a simulation's event windows until a stop criterion holds (the loop of :func:`compress`).

    Resumes from ``checkpoint`` when it holds a state of the same ``fingerprint``; switches to
    ``final_growth_rate`` at the first window whose reduced pressure reaches ``switch_pressure``;
    refuses to go on when a run towards ``stop.target_phi`` jammed short of it; logs progress,
    writes checkpoints every ``checkpoint_interval`` seconds at points where the continuation is
    bit-identical, and on SIGINT / SIGTERM saves and raises
    :class:`hardpack.io.interrupt.Interrupted`.

    Parameters
    ----------
    sim : Simulation or EllipsoidSimulation
        Anything with ``run_window``, ``growth_rate``, ``n``, ``collisions``, ``windows``,
        ``records``, ``checkpoint_ready``, ``state()`` and ``restore()``.
    stop : StopCriteria
        When to stop.
    stage_window : callable
        Collisions per particle of a window at a growth rate.
    checkpoint : path or None
        Resumable checkpoint.
    fingerprint : str
        :func:`hardpack.io.checkpoint.fingerprint` of the run's inputs.
    final_growth_rate, switch_pressure, progress, progress_interval, checkpoint_interval
        As for :func:`compress`.
    label : str
        Prefix of the progress log lines.

    Returns
    -------
    str
        The stop reason.
    """
    state = None if checkpoint is None else ckpt.load(checkpoint, fingerprint)
    if state is not None:
        sim.restore(state)
    started = time.perf_counter()
    last_ckpt = last_log = started
    last_coll = sim.collisions
    with interrupt.deferred():
        if state is not None:  # announced once a signal can no longer stop the run before a save
            log.info("resumed from %s at window %d (%d collisions)", checkpoint, sim.windows,
                     sim.collisions)
        while (reason := _stop_reason(stop, sim, started)) is None:
            budget = max(1, round(stage_window(sim.growth_rate) * sim.n))
            if stop.max_collisions is not None:
                budget = min(budget, int(stop.max_collisions) - sim.collisions)
            record = sim.run_window(budget, stop.target_phi)
            _jammed_short(stop, record, sim.growth_rate)
            if final_growth_rate is not None and sim.growth_rate != final_growth_rate \
                    and record["Z"] >= switch_pressure:
                sim.growth_rate = float(final_growth_rate)
                log.info("Z=%.4g >= %.4g after %d collisions: growth rate now %g", record["Z"],
                         switch_pressure, sim.collisions, final_growth_rate)
            if progress is not None:
                progress(record)
            now = time.perf_counter()
            if now - last_log >= progress_interval:
                log.info("%sphi=%.6f Z=%.4g phi_J_est=%.6f collisions=%d (%.3g /s)", label, record["phi"],
                         record["Z"], record["phi_J_est"], sim.collisions,
                         (sim.collisions - last_coll) / (now - last_log))
                last_log, last_coll = now, sim.collisions
            if interrupt.requested() is not None and (checkpoint is None or sim.checkpoint_ready):
                if checkpoint is not None:
                    ckpt.save(checkpoint, fingerprint, sim.state())
                raise interrupt.stop(checkpoint, f"phi = {record['phi']:.6f}, Z = {record['Z']:.4g}, "
                                                 f"{sim.collisions} collisions")
            if checkpoint is not None and now - last_ckpt >= checkpoint_interval \
                    and sim.checkpoint_ready and _stop_reason(stop, sim, started) is None:
                ckpt.save(checkpoint, fingerprint, sim.state())
                last_ckpt = time.perf_counter()
    return reason


def compress(packing: Packing, growth_rate: float, seed: int, stop: StopCriteria | None = None,
             checkpoint=None, progress=None, *, window: float | None = None,
             checkpoint_interval: float = 300.0, progress_interval: float = 10.0,
             overlap_tol: float = DEFAULT_OVERLAP_TOL, final_growth_rate: float | None = None,
             switch_pressure: float = 1e3, contact_forces: bool = False,
             contact_windows: int = 10, keep_checkpoint: bool = False) -> CompressResult:
    """LS compression of ``packing`` at growth rate ``growth_rate`` (Gamma, module docstring).

    seed: initial Maxwell-Boltzmann velocities from numpy default_rng(seed) (the only randomness).
    stop: :class:`StopCriteria` (default: reduced pressure 1e12).
    checkpoint: path of an atomic checkpoint written at synchronisation points every
    ``checkpoint_interval`` seconds; if it exists (same packing, rates, seed, window, contact
    options) the run resumes from it and ends bit-identical to an uninterrupted run. Removed on
    success unless ``keep_checkpoint`` (then the caller removes it once the result is safely
    written). On SIGINT or SIGTERM the run writes its checkpoint at the next point where it can
    resume exactly (at most ``SORT_EVERY`` windows later) and raises
    :class:`hardpack.io.interrupt.Interrupted`.
    progress: callable receiving each window's record (dict); progress lines also go to the
    ``hardpack.md`` logger every ``progress_interval`` seconds.
    window: collisions per particle between synchronisations (default :func:`default_window` of
    the rate of the current stage).
    overlap_tol: relative overlap tolerance checked at every synchronisation and at the end.
    final_growth_rate, switch_pressure: two-stage protocol (module docstring): from the first
    window whose reduced pressure reaches ``switch_pressure`` on, grow at ``final_growth_rate``.
    contact_forces: accumulate the per-pair collision impulses over the last ``contact_windows``
    windows (:mod:`hardpack.md.contacts`); ``result.contacts`` then holds the time-averaged
    contact forces and :meth:`CompressResult.save` stores them with the packing.

    Parameters
    ----------
    packing : Packing
        Start configuration: a sphere packing in an orthorhombic cell without overlaps: periodic
        (N >= 2), with hard walls on some axes or in a spherical container (N >= 1; the walls stay
        fixed while the spheres grow, Donev 2006, Ch. 7).
    growth_rate : float
        Gamma = (d<D>/dt) / sqrt(kT/m), finite; negative shrinks the particles (needs a
        ``target_phi`` below the start), 0 runs at fixed phi (needs a collision or time limit).
    seed : int
        Non-negative seed of the initial Maxwell-Boltzmann velocities (the only randomness).
    stop : StopCriteria, optional
        Default: reduced pressure 1e12.
    checkpoint : str or os.PathLike, optional
        Path of the resumable checkpoint described above.
    progress : callable, optional
        Receives each window's record (a dict).
    window : float, optional
        Collisions per particle between synchronisations (> 0); default :func:`default_window`
        of the current stage's rate.
    checkpoint_interval : float, default 300.0
        Seconds between checkpoint writes.
    progress_interval : float, default 10.0
        Seconds between progress log lines.
    overlap_tol : float, default DEFAULT_OVERLAP_TOL
        Relative overlap tolerance checked at every synchronisation and at the end.
    final_growth_rate : float, optional
        Growth rate (finite, > 0) of the slow second stage; needs growth_rate > 0.
    switch_pressure : float, default 1e3
        Reduced pressure (finite, > 1, below ``stop.max_pressure``) that starts the slow stage.
    contact_forces : bool, default False
        Accumulate the MD contact forces.
    contact_windows : int, default 10
        Windows over which they are averaged (a positive integer).
    keep_checkpoint : bool, default False
        Leave the checkpoint for the caller to remove.

    Returns
    -------
    CompressResult
        The final packing and velocities, the per-window ``timeseries`` Dataset, the run
        ``stats`` (stop reason, final Z, phi, phi_J_est, counts, end-state checks) and the MD
        ``contacts`` when asked for.

    Raises
    ------
    InvalidInputError
        If the packing cannot be run (not periodic spheres, sheared cell, fewer than 2
        particles, overlaps); ``growth_rate``, ``seed``, ``window``, ``contact_windows`` or the
        two-stage parameters are invalid; the stop criteria are impossible or never end
        (:meth:`StopCriteria.check`); or a run towards ``target_phi`` without a pressure cap
        jammed short of it (reduced pressure above JAMMED_PRESSURE with phi_J_est below the
        target).
    OverlapError
        If particles overlap beyond ``overlap_tol`` at a synchronisation point (an engine
        failure).
    hardpack.io.interrupt.Interrupted
        On SIGINT or SIGTERM, after the checkpoint is written.
    """
    check_packing(packing)
    stop = _check_run_options(packing, growth_rate, seed, stop, final_growth_rate, switch_pressure, window)
    if contact_forces and packing.boundary.kind != "periodic":
        raise InvalidInputError("MD contact forces log pair collisions only; with hard walls the wall "
                                "forces would be missing: compute forces from the packing "
                                "(hardpack.jamming) or use a periodic cell")
    if contact_forces and (isinstance(contact_windows, bool) or int(contact_windows) != contact_windows
                           or contact_windows < 1):
        raise InvalidInputError(f"contact_windows must be a positive integer, got {contact_windows!r}")

    def stage_window(rate: float) -> float:
        return default_window(rate, packing.dim) if window is None else float(window)

    sim = Simulation(packing, maxwell_boltzmann(packing.n_particles, packing.dim, seed),
                     growth_rate, overlap_tol=overlap_tol,
                     contact_windows=int(contact_windows) if contact_forces else 0)
    fp = ckpt.fingerprint(packing, growth_rate=float(growth_rate), seed=int(seed), window=window,
                          overlap_tol=overlap_tol, final_growth_rate=final_growth_rate,
                          switch_pressure=float(switch_pressure) if final_growth_rate else None,
                          contact_windows=int(contact_windows) if contact_forces else 0,
                          **({} if packing.boundary.kind == "periodic" else {"boundary": str(packing.boundary)}))
    reason = run_windows(sim, stop, stage_window, checkpoint, fp, final_growth_rate=final_growth_rate,
                         switch_pressure=switch_pressure, progress=progress, progress_interval=progress_interval,
                         checkpoint_interval=checkpoint_interval)

    final = sim.packing()
    report = final.overlap_report(overlap_tol)
    last = {k: (sim.records[k][-1] if sim.records[k] else float("nan")) for k in ("Z", "phi_J_est")}
    rates = np.asarray(sim.records["growth_rate"])
    colls = np.asarray(sim.records["collisions"])
    first_slow = np.flatnonzero(rates != growth_rate) if final_growth_rate is not None else []
    switch_coll = (int(colls[first_slow[0] - 1]) if first_slow[0] > 0 else 0) if len(first_slow) else None
    stats = {
        "protocol": "lubachevsky_stillinger" if final_growth_rate is None
        else "lubachevsky_stillinger_two_stage",
        "growth_rate": float(growth_rate), "seed": int(seed),
        "stop_reason": reason, "Z": float(last["Z"]), "phi": float(final.phi),
        "phi_J_est": float(last["phi_J_est"]), "collisions": int(sim.collisions),
        "events": int(sim.events), "windows": int(sim.windows), "md_time": float(sim.time),
        "wall_time": float(sim.wall_time), "window_collisions_per_particle": stage_window(growth_rate),
        "overlap_tol": overlap_tol,
        # largest 1 - r/(a_i + a_j) over listed (near) pairs at the end: about minus the smallest
        # relative gap, positive only for overlaps; the independent check is overlap_report's
        "max_overlap": float(sim.records["max_overlap"][-1]) if sim.records["max_overlap"] else float("nan"),
        "n_overlapping": int(report.n_overlapping),
        "overlap_check": "passed" if report.n_overlapping == 0 else "failed",
        "mass": 1.0, "kT": 1.0,
    }
    if sim.boundary.kind != "periodic":
        stats["Z_wall"] = float(sim.records["Z_wall"][-1]) if sim.records["Z_wall"] else float("nan")
    if final_growth_rate is not None:
        stats.update({
            "final_growth_rate": float(final_growth_rate), "switch_pressure": float(switch_pressure),
            "final_window_collisions_per_particle": stage_window(final_growth_rate),
            # collisions when the slow stage began (None: Z never reached switch_pressure)
            "switch_collisions": switch_coll,
            "final_stage_collisions": None if switch_coll is None else int(sim.collisions) - switch_coll,
        })
    if reason == "max_pressure":
        _end_state_check(final, stats)
    contacts = None
    if contact_forces:
        contacts = sim.contacts.result(final)
        stats.update(contacts.attrs)
    ts_attrs = {k: stats[k] for k in ("growth_rate", "seed", "stop_reason", "final_growth_rate",
                                      "switch_pressure") if k in stats}
    ts = timeseries_dataset(sim, ts_attrs | {"N": sim.n, "d": sim.d, "phi_start": float(packing.phi)})
    if checkpoint is not None and not keep_checkpoint:
        ckpt.remove(checkpoint)
    return CompressResult(final, sim.velocities(), ts, stats, contacts)
