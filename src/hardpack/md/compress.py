"""Lubachevsky-Stillinger (LS) compression: event-driven MD with growing spheres.

Protocol (Donev dissertation ch. 1, note 000_ch1-3_md.md sec. 2.1; Ogarko sec. 2.5): start from a
non-overlapping packing, draw Maxwell-Boltzmann velocities (kT = m = 1), grow every radius in
proportion to its size while running collision-driven MD, rescale velocities to kT = 1 at every
synchronisation point, and stop at a reduced pressure (default 1e12), a volume fraction, a number
of collisions or a wall-clock limit.

**Growth rate.** ONE dimensionless rate Gamma = (d<D>/dt) / sqrt(kT/m): the growth speed of the
mean diameter in units of the thermal speed (kT = m = 1). Radii grow linearly in time,
a_i(t) = a_i(0) (1 + 2 Gamma t / <D>(0)), so every particle keeps its size relative to the others.
Conversions to the seeds' conventions:

- Skoge/Donev ``growthrate`` g (PackLSD/"spheres" code, note 000 sec. 1): a RADIUS rate
  dr/dt = g with velocities rescaled to <v^2> = 1, i.e. kT/m = 1/d:  Gamma = 2 sqrt(d) g.
- Donev's text gamma (L2680, radius rate in units of sqrt(kT/m)): Gamma = 2 gamma; L436 uses a
  diameter rate, for which Gamma = gamma.
- Ogarko Gamma_O (Eq. 3.32: da_i/dt = Gamma_O (a_i/a_max) v0, v0 = sqrt(2E/(3M)) = sqrt(kT/m)
  in 3D): Gamma = 2 Gamma_O <a>/a_max (= 2 Gamma_O for monodisperse spheres).

**Pressure.** Per window Z = pV/(NkT) = 1 + sum_coll r_ij . J_ij / (d N kT dt) with kT the
window's time-averaged kinetic temperature (note sec. 2.5; Z = 1 + virial / (2 * integral of
KE dt)); the running jamming-density estimate is phi_J_est = phi / (1 - d/Z), the free-volume form
p = d / (1 - phi/phi_J) (Eqs. 1.1-1.2, L330-351).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, Packing
from hardpack.md import checkpoint as ckpt
from hardpack.md.simulation import (
    RECORD_FIELDS,
    Simulation,
    check_packing,
    maxwell_boltzmann,
)

log = logging.getLogger("hardpack.md")

#: default heating per window: collisions per particle ~ HEATING * d / Gamma (see default_window)
HEATING = 0.03
MAX_WINDOW = 20.0


@dataclass(frozen=True)
class StopCriteria:
    """Composable stop criteria, checked at every synchronisation point; the first met stops.

    max_pressure: reduced pressure Z (growing runs only); target_phi: volume fraction (reached
    exactly: the last window ends when phi hits it); max_collisions: total collisions;
    max_wall_time: seconds of wall-clock time in this invocation. None disables a criterion.
    """

    max_pressure: float | None = 1e12
    target_phi: float | None = None
    max_collisions: int | None = None
    max_wall_time: float | None = None

    def check(self, growth_rate: float, phi: float) -> None:
        """Refuse impossible or never-ending combinations for this growth rate and start phi."""
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
    """Final packing, final velocities (m = 1, kT = 1), per-window time series and run stats."""

    packing: Packing
    velocities: np.ndarray
    timeseries: xr.Dataset
    stats: dict = field(default_factory=dict)

    def save(self, packing_path, timeseries_path=None, config=None):
        """Write the packing (with the stats as attributes) and optionally the time series."""
        from hardpack.io import save_packing, write_dataset

        save_packing(self.packing, packing_path, attrs=self.stats, config=config,
                     seed=self.stats.get("seed"))
        if timeseries_path is not None:
            write_dataset(self.timeseries, timeseries_path, config=config, seed=self.stats.get("seed"))


def default_window(growth_rate: float, d: int) -> float:
    """Collisions per particle per synchronisation window.

    With equal masses each collision adds g |v_n| of kinetic energy, so the relative heating per
    collision per particle is about 2 Gamma sqrt(pi) / d (mean |v_n| of colliding pairs sqrt(pi kT)
    and g / sigma = Gamma / <D>). HEATING * d / Gamma collisions per particle keep the heating
    between rescalings near 10 %, capped at MAX_WINDOW (Skoge-Donev use ~20 events per particle).
    """
    if growth_rate == 0:
        return MAX_WINDOW
    return float(np.clip(HEATING * d / abs(growth_rate), 1.0, MAX_WINDOW))


def timeseries_dataset(sim: Simulation, attrs: dict) -> xr.Dataset:
    """The window records as an xarray Dataset with dimension ``window``."""
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
    }
    data = {k: ("window", np.asarray(sim.records[k], dtype=float), {"description": units[k]})
            for k in RECORD_FIELDS}
    ds = xr.Dataset(data, coords={"window": np.arange(len(sim.records["time"]))})
    ds.attrs.update({"hardpack_kind": "md_timeseries", **attrs})
    return ds


def _stop_reason(stop: StopCriteria, sim: Simulation, started: float) -> str | None:
    rec = sim.records
    if rec["Z"]:
        if sim.growth_rate > 0 and stop.max_pressure is not None and rec["Z"][-1] >= stop.max_pressure:
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


def compress(packing: Packing, growth_rate: float, seed: int, stop: StopCriteria | None = None,
             checkpoint=None, progress=None, *, window: float | None = None,
             checkpoint_interval: float = 300.0, progress_interval: float = 10.0,
             overlap_tol: float = DEFAULT_OVERLAP_TOL) -> CompressResult:
    """LS compression of ``packing`` at growth rate ``growth_rate`` (Gamma, module docstring).

    seed: initial Maxwell-Boltzmann velocities from numpy default_rng(seed) (the only randomness).
    stop: :class:`StopCriteria` (default: reduced pressure 1e12).
    checkpoint: path of an atomic checkpoint written at synchronisation points every
    ``checkpoint_interval`` seconds; if it exists (same packing, rate, seed, window) the run
    resumes from it and ends bit-identical to an uninterrupted run. Removed on success.
    progress: callable receiving each window's record (dict); progress lines also go to the
    ``hardpack.md`` logger every ``progress_interval`` seconds.
    window: collisions per particle between synchronisations (default :func:`default_window`).
    overlap_tol: relative overlap tolerance checked at every synchronisation and at the end.
    """
    check_packing(packing)
    if isinstance(growth_rate, bool) or not isinstance(growth_rate, (int, float, np.floating, np.integer)) \
            or not math.isfinite(growth_rate):
        raise InvalidInputError(f"growth_rate must be a finite number, got {growth_rate!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError(f"seed must be a non-negative integer, got {seed!r}")
    stop = StopCriteria() if stop is None else stop
    stop.check(float(growth_rate), packing.phi)
    window = default_window(growth_rate, packing.dim) if window is None else float(window)
    if not (math.isfinite(window) and window > 0):
        raise InvalidInputError(f"window must be a positive number of collisions per particle, got {window!r}")

    sim = Simulation(packing, maxwell_boltzmann(packing.n_particles, packing.dim, seed),
                     growth_rate, overlap_tol=overlap_tol)
    fp = ckpt.fingerprint(packing, growth_rate=float(growth_rate), seed=int(seed), window=window,
                          overlap_tol=overlap_tol)
    if checkpoint is not None:
        state = ckpt.load(checkpoint, fp)
        if state is not None:
            sim.restore(state)
            log.info("resumed from %s at window %d (%d collisions)", checkpoint, sim.windows,
                     sim.collisions)
    coll_per_window = max(1, round(window * sim.n))
    started = time.perf_counter()
    last_ckpt = last_log = started
    last_coll = sim.collisions
    while (reason := _stop_reason(stop, sim, started)) is None:
        budget = coll_per_window
        if stop.max_collisions is not None:
            budget = min(budget, int(stop.max_collisions) - sim.collisions)
        record = sim.run_window(budget, stop.target_phi)
        if progress is not None:
            progress(record)
        now = time.perf_counter()
        if now - last_log >= progress_interval:
            log.info("phi=%.6f Z=%.4g phi_J_est=%.6f collisions=%d (%.3g /s)", record["phi"],
                     record["Z"], record["phi_J_est"], sim.collisions,
                     (sim.collisions - last_coll) / (now - last_log))
            last_log, last_coll = now, sim.collisions
        if checkpoint is not None and now - last_ckpt >= checkpoint_interval \
                and sim.checkpoint_ready and _stop_reason(stop, sim, started) is None:
            ckpt.save(checkpoint, fp, sim.state())
            last_ckpt = time.perf_counter()

    final = sim.packing()
    report = final.overlap_report(overlap_tol)
    last = {k: (sim.records[k][-1] if sim.records[k] else float("nan")) for k in ("Z", "phi_J_est")}
    stats = {
        "protocol": "lubachevsky_stillinger", "growth_rate": float(growth_rate), "seed": int(seed),
        "stop_reason": reason, "Z": float(last["Z"]), "phi": float(final.phi),
        "phi_J_est": float(last["phi_J_est"]), "collisions": int(sim.collisions),
        "events": int(sim.events), "windows": int(sim.windows), "md_time": float(sim.time),
        "wall_time": float(sim.wall_time), "window_collisions_per_particle": window,
        "overlap_tol": overlap_tol, "max_overlap": float(report.overlap),
        "n_overlapping": int(report.n_overlapping),
        "overlap_check": "passed" if report.n_overlapping == 0 else "failed",
        "mass": 1.0, "kT": 1.0,
    }
    ts = timeseries_dataset(sim, {k: stats[k] for k in ("growth_rate", "seed", "stop_reason")}
                            | {"N": sim.n, "d": sim.d})
    if checkpoint is not None:
        ckpt.remove(checkpoint)
    return CompressResult(final, sim.velocities(), ts, stats)
