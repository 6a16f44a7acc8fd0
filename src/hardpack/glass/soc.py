"""Compression of a single-occupancy-cell (SOC) solid: growing disks or spheres, each confined to a
fixed cell around its start position (Donev 2006, sec. 13.3.1, Fig. 13.9).

Model and conventions (Donev 2006 states the model, not the algorithm; our choices are stated):

- The cell of particle i is a ball of radius (1 + Delta mu) R_i^0 centred on its start position
  R_i^0 (the bounding cells of BCMD, :mod:`hardpack.freeenergy.bcmd`; Fig. 13.9 uses
  Delta mu = 1, "a cell of twice its size"). The particle must stay inside it, so its centre stays
  within (1 + Delta mu) R_i^0 - R_i(t) of R_i^0. The cells are fixed; the particles grow.
- Growth as in the LS engine (:mod:`hardpack.md.simulation`): radii grow in proportion to their
  size, the mean diameter at d<D>/dt = ``growth_rate`` (Gamma), masses 1, velocities rescaled to
  kT = 1 at the start of every segment. A segment runs the event loop of BCMD
  (:func:`hardpack.freeenergy._kernel.run_segment`) with the centres' room shrinking at the
  growth rate and the pair contact distances growing with it.
- Pressure as Donev measures it: the reduced pressure Z = pV/(NkT) from the momentum exchanged
  in pair collisions only, Z = 1 + sum(J sigma) / (2 int KE dt) per segment, without the
  pressure on the cell walls (recorded apart as ``p_c``, the reduced cell pressure of
  :mod:`hardpack.freeenergy.bcmd`). The jamming density is estimated by free-volume theory,
  phi_J ~ phi / (1 - d / Z) (Donev 2006, Eq. 1.2; exact as Z -> inf for a crystal, Salsburg & Wood
  1962).
- A run stops when Z reaches ``max_pressure`` ("to near jamming"), phi reaches ``target_phi``, or
  the cells leave less than ``MIN_ROOM`` of a radius of room (a particle fills its cell).

The cells are static, so the pair list (the pairs whose cells overlap) is built once. Lengths are
those of the packing; time is in units of (mean diameter) / (thermal speed) like the LS engine's.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.freeenergy import _kernel as kern
from hardpack.freeenergy.bcmd import cell_neighbours
from hardpack.geometry.packing import Packing
from hardpack.io import checkpoint as ckpt
from hardpack.io import interrupt

log = logging.getLogger(__name__)

#: a run stops when the centres' room falls below this fraction of the current radius
MIN_ROOM = 1e-3
#: seconds of CPU time between progress lines
PROGRESS_INTERVAL = 60.0
#: a segment ends early after this many times its target events: where a cluster jams in its cells
#: (at fast growth) the collision rate diverges there, and the segment's Z shows it
EVENT_BUDGET = 10

_COLUMNS = ("time", "phi", "phi_mid", "Z", "phi_J_est", "p_c", "kT_mean", "events", "pair_collisions",
            "wall_collisions")


@dataclass(frozen=True)
class SOCResult:
    """Outcome of :func:`compress_in_cells`.

    Attributes
    ----------
    packing : Packing
        The final packing (centres inside their cells, radii grown), cells not stored.
    timeseries : xarray.Dataset
        One row per segment (dimension ``segment``): ``time``, ``phi`` (at the segment end),
        ``phi_mid``, ``Z`` (pair-collision pressure), ``phi_J_est``, ``p_c`` (cell-wall
        pressure), ``kT_mean``, event counts; run parameters and the outcome in its attrs
        (``hardpack_kind`` = "soc_compression").
    stop : str
        "max_pressure", "target_phi" or "cell_filled".
    """

    packing: Packing
    timeseries: xr.Dataset
    stop: str


def _positive(name, value, lo=0.0):
    if isinstance(value, bool):
        raise InvalidInputError(f"{name} must be a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(x) and x > lo):
        raise InvalidInputError(f"{name} = {value!r} must be finite and > {lo:g}")
    return x


def compress_in_cells(
    packing: Packing,
    *,
    dmu: float = 1.0,
    growth_rate: float = 1e-6,
    max_pressure: float | None = 1e3,
    target_phi: float | None = None,
    seed: int = 0,
    window: float = 100.0,
    checkpoint=None,
    checkpoint_interval: float = 600.0,
) -> SOCResult:
    """Compress ``packing`` with every particle confined to a fixed cell of radius
    (1 + ``dmu``) R around its start position (module docstring; Donev 2006, Fig. 13.9).

    Parameters
    ----------
    packing : Packing
        A periodic sphere (or disk) packing without overlaps; its positions are the cell centres.
    dmu : float, default 1.0
        Cell size Delta mu > 0 in units of each particle's start radius.
    growth_rate : float, default 1e-6
        d<D>/dt > 0 of the mean diameter, in thermal-speed units (the LS engine's Gamma).
    max_pressure : float or None, default 1e3
        Stop when a segment's pair-collision pressure Z reaches it (> 1).
    target_phi : float or None
        Stop when phi reaches it (above the start phi).
    seed : int, default 0
        Seed of the Maxwell-Boltzmann start velocities.
    window : float, default 100.0
        Collisions per particle per segment (one record per segment; the segment's duration is
        adapted to it).
    checkpoint : str or os.PathLike, optional
        Checkpoint file: written every ``checkpoint_interval`` seconds and on SIGINT / SIGTERM,
        loaded on a restart with the same inputs (the continued run is bit-identical), removed
        at the end.
    checkpoint_interval : float, default 600.0
        Seconds between checkpoints.

    Returns
    -------
    SOCResult
        The final packing, the per-segment time series and the stop reason.

    Raises
    ------
    InvalidInputError
        If the packing is not a periodic sphere packing, overlaps, or a parameter is out of range,
        or neither ``max_pressure`` nor ``target_phi`` is given.
    RuntimeError
        If a segment's ``EVENT_BUDGET`` times its expected events take no time, a particle leaves
        its cell or two particles overlap (failures of the dynamics, not of the input).
    hardpack.io.interrupt.Interrupted
        On SIGINT / SIGTERM, after writing the checkpoint.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError("packing must be a hardpack Packing")
    packing.require_periodic_spheres("the SOC compression")
    dmu = _positive("dmu", dmu)
    growth_rate = _positive("growth_rate", growth_rate)
    window = _positive("window", window)
    if max_pressure is None and target_phi is None:
        raise InvalidInputError("no stop criterion: give max_pressure, target_phi or both")
    if max_pressure is not None:
        max_pressure = _positive("max_pressure", max_pressure, lo=1.0)
    phi0 = packing.phi
    if target_phi is not None:
        target_phi = _positive("target_phi", target_phi, lo=phi0)
    worst = packing.overlap_report(tol=0.0).overlap
    if worst > 1e-9:
        raise InvalidInputError(f"the start packing overlaps (worst relative overlap {worst:.3g}): the cells would "
                                "start infeasible; start from an MD snapshot or LS packing")
    n, d = packing.n_particles, packing.dim
    nb = cell_neighbours(packing, dmu)
    end_all = nb.start[1:].copy()
    r0 = packing.radii.astype(float)
    mean_d0 = 2.0 * float(r0.mean())

    fp = ckpt.fingerprint(packing, run="soc", dmu=dmu, growth_rate=growth_rate, seed=int(seed), window=window)
    state = None if checkpoint is None else ckpt.load(checkpoint, fp)
    if state is not None:
        P = np.array(state["P"], float)
        scale, dt = float(state["scale"]), float(state["dt"])
        t = float(state["time"])
        rows = [tuple(r) for r in state["records"].tolist()]
        totals = np.array(state["totals"], np.int64)
    else:
        rng = np.random.default_rng(seed)
        P = np.zeros((n, 2 * d + 1))
        P[:, d:2 * d] = rng.normal(size=(n, d))
        scale = 1.0  # radii are scale * r0
        dt = 0.01 * window * mean_d0
        t = 0.0
        rows = []
        totals = np.zeros(kern.N_INT, np.int64)
    invm = np.ones(n)
    v = P[:, d:2 * d]
    target_events = window * n
    stop = None
    cpu_start = time.process_time()
    reported, last_save = cpu_start, time.perf_counter()
    with interrupt.deferred():
        if state is not None:
            log.info("resumed from %s at segment %d (phi = %.6f)", checkpoint, len(rows), phi0 * scale**d)
        while stop is None:
            if interrupt.requested() is not None:
                if checkpoint is not None:
                    _save(checkpoint, fp, P, scale, dt, t, rows, totals)
                raise interrupt.stop(checkpoint, f"segment {len(rows)} (phi = {phi0 * scale**d:.6f})")
            if checkpoint is not None and time.perf_counter() - last_save >= checkpoint_interval:
                _save(checkpoint, fp, P, scale, dt, t, rows, totals)
                last_save = time.perf_counter()
            if time.process_time() - reported >= PROGRESS_INTERVAL:
                reported = time.process_time()
                z = rows[-1][3] if rows else float("nan")
                log.info("SOC: segment %d, phi = %.6f, Z = %.4g, %.3g events", len(rows), phi0 * scale**d, z,
                         float(totals[kern.C_EVENTS]))
            v *= math.sqrt(d * n / float(np.sum(v * v)))  # kT = 1
            radii = scale * r0
            room = (1.0 + dmu) / scale - 1.0  # centre room in current radii
            kappa = growth_rate / (scale * mean_d0)  # relative radius growth rate
            seg = min(dt, 0.5 * (room - MIN_ROOM) / kappa)
            if target_phi is not None:
                seg = min(seg, ((target_phi / phi0) ** (1.0 / d) / scale - 1.0) / kappa)
            facc = np.zeros(kern.N_FLOAT)
            iacc = np.zeros(kern.N_INT, np.int64)
            budget = int(EVENT_BUDGET * target_events)
            kern.run_segment(P, radii, invm, nb.start, end_all, nb.j, nb.disp, nb.sig * scale, room, kappa,
                             seg, facc, iacc, budget, kappa)
            seg = facc[kern.F_END_TIME]  # shorter when the event budget ended it (a cluster jamming in its cells)
            if not seg > 0.0:
                raise RuntimeError(f"{budget} events took no time at phi = {phi0 * scale**d:.6f}: the dynamics "
                                   "ran away")
            totals += iacc
            scale_mid = scale * (1.0 + 0.5 * kappa * seg)
            scale *= 1.0 + kappa * seg
            t += seg
            ke_int = facc[kern.F_KE_INTEGRAL]
            z = 1.0 + facc[kern.F_PAIR_VIRIAL] / (2.0 * ke_int)
            kt_mean = 2.0 * ke_int / (d * n * seg)
            p_c = facc[kern.F_WALL_IMPULSE_R] * (1.0 + room) / (d * n * seg * kt_mean)  # (1 + room) R: the cell
            phi, phi_mid = phi0 * scale**d, phi0 * scale_mid**d
            phi_j = phi_mid / (1.0 - d / z) if z > d else np.nan
            rows.append((t, phi, phi_mid, z, phi_j, p_c, kt_mean, iacc[kern.C_EVENTS], iacc[kern.C_PAIR],
                         iacc[kern.C_WALL]))
            if max_pressure is not None and z >= max_pressure:
                stop = "max_pressure"
            elif target_phi is not None and phi >= target_phi * (1.0 - 1e-12):
                stop = "target_phi"
            elif (1.0 + dmu) / scale - 1.0 <= MIN_ROOM * 1.000001:
                stop = "cell_filled"
            events = max(int(iacc[kern.C_EVENTS]), 1)
            dt = seg * min(2.0, max(0.5, target_events / events))
    final = _final_packing(packing, P[:, :d], scale, nb, dmu)
    arr = np.array(rows, float).reshape(-1, len(_COLUMNS))
    data = {name: ("segment", arr[:, k]) for k, name in enumerate(_COLUMNS)}
    for name in ("events", "pair_collisions", "wall_collisions"):
        data[name] = ("segment", arr[:, _COLUMNS.index(name)].astype(np.int64))
    last = rows[-1]
    attrs = {
        "hardpack_kind": "soc_compression", "n_particles": n, "dim": d, "phi0": phi0, "dmu": dmu,
        "growth_rate": growth_rate, "max_pressure": -1.0 if max_pressure is None else max_pressure,
        "target_phi": -1.0 if target_phi is None else target_phi, "seed": int(seed), "window": window,
        "stop": stop, "phi_final": final.phi, "Z_final": last[3], "phi_J_est": last[4],
        "n_events": int(totals[kern.C_EVENTS]), "n_pair": int(totals[kern.C_PAIR]),
        "n_wall": int(totals[kern.C_WALL]), "cpu_seconds_this_run": time.process_time() - cpu_start,
    }
    ts = xr.Dataset(data, attrs=attrs)
    ts["Z"].attrs["long_name"] = "reduced pressure pV/(NkT) from pair collisions"
    ts["p_c"].attrs["long_name"] = "reduced cell-wall pressure (hardpack.freeenergy.bcmd)"
    ts["phi_J_est"].attrs["long_name"] = "phi_mid / (1 - d / Z)"
    if checkpoint is not None:
        ckpt.remove(checkpoint)
    log.info("SOC compression from phi0 = %.5f stopped (%s) at phi = %.6f, Z = %.4g, phi_J ~ %.5f after %d events",
             phi0, stop, final.phi, last[3], last[4], attrs["n_events"])
    return SOCResult(final, ts, stop)


def _final_packing(packing: Packing, dr: np.ndarray, scale: float, nb, dmu: float) -> Packing:
    """The grown packing with its centres moved off the cell centres; refused if a centre left its
    cell or two particles overlap (beyond round-off)."""
    r = scale * packing.radii
    room = (1.0 + dmu) * packing.radii - r
    excursion = float(np.max(np.linalg.norm(dr, axis=1) / room)) if len(r) else 0.0
    if excursion > 1.0 + 1e-8:
        raise RuntimeError(f"a particle left its cell (|dr| / room = {excursion:.12g})")
    i = np.repeat(np.arange(nb.start.size - 1), np.diff(nb.start))
    sep = nb.disp + dr[nb.j] - dr[i]
    if sep.size and float(np.min(np.linalg.norm(sep, axis=1) / (scale * nb.sig))) < 1.0 - 1e-9:
        raise RuntimeError("two particles overlap at the end of the SOC compression")
    return packing.replace(positions=packing.positions + dr, radii=r).wrapped()


def _save(path, fp, P, scale, dt, t, rows, totals) -> None:
    ckpt.save(path, fp, {"P": P, "scale": scale, "dt": dt, "time": t,
                         "records": np.asarray(rows, float).reshape(-1, len(_COLUMNS)), "totals": totals})


#: fraction of a relaxation's blocks (the last ones) whose mean pressure gives the relaxed phi_J
RELAXED_TAIL = 0.25


def soc_summary(timeseries, relaxations) -> xr.Dataset:
    """phi_J of SOC solids at the end of their compression and after relaxation without cells, per
    start density phi_0 and seed (Donev 2006, sec. 13.3.1, Fig. 13.9).

    Parameters
    ----------
    timeseries : sequence of xarray.Dataset
        SOC compressions (:func:`compress_in_cells` time series, ``hardpack_kind`` =
        "soc_compression").
    relaxations : sequence of xarray.Dataset
        For each of them, in the same order, NVE MD of its final packing with the cells removed
        (``hardpack eos``: ``Z_block`` per block, ``phi`` in its attributes).

    Returns
    -------
    xarray.Dataset
        Dimensions ``phi0`` and ``seed``: ``phi_soc``, ``Z_soc``, ``phi_J_soc`` (phi / (1 - d / Z)
        at the end of the compression), ``Z_relaxed`` (mean of the last ``RELAXED_TAIL`` of the
        blocks), ``phi_J_relaxed``; NaN where a (phi0, seed) was not run.

    Raises
    ------
    InvalidInputError
        If the lists differ in length, a dataset is of the wrong kind, a relaxation was run at
        another phi than its compression ended at, or two compressions share (phi0, seed) or differ
        in N, dmu or rate.
    """
    timeseries, relaxations = list(timeseries), list(relaxations)
    if len(timeseries) != len(relaxations) or not timeseries:
        raise InvalidInputError(f"give one relaxation per SOC compression (got {len(timeseries)} compressions "
                                f"and {len(relaxations)} relaxations)")
    keys = ("n_particles", "dim", "dmu", "growth_rate", "max_pressure")
    first = timeseries[0].attrs
    rows = {}
    for ts, rel in zip(timeseries, relaxations):
        if ts.attrs.get("hardpack_kind") != "soc_compression" or "Z_block" not in rel:
            raise InvalidInputError("soc_summary takes SOC compression time series and `hardpack eos` relaxations")
        if any(ts.attrs[k] != first[k] for k in keys):
            raise InvalidInputError(f"the SOC compressions differ in {', '.join(keys)}: summarise one protocol")
        if not math.isclose(float(rel.attrs["phi"]), float(ts.attrs["phi_final"]), rel_tol=1e-9):
            raise InvalidInputError(f"a relaxation at phi = {float(rel.attrs['phi']):.8f} does not start from the SOC "
                                    f"packing at phi = {float(ts.attrs['phi_final']):.8f}: pair them in order")
        key = (round(float(ts.attrs["phi0"]), 6), int(ts.attrs["seed"]))
        if key in rows:
            raise InvalidInputError(f"two SOC compressions from phi0 = {key[0]:g}, seed {key[1]}")
        z = np.asarray(rel["Z_block"].values, float)
        z_rel = float(np.mean(z[-max(1, int(round(RELAXED_TAIL * z.size))):]))
        rows[key] = (float(ts.attrs["phi_final"]), float(ts["Z"].values[-1]), float(ts.attrs["phi_J_est"]), z_rel)
    phi0s = sorted({k[0] for k in rows})
    seeds = sorted({k[1] for k in rows})
    d = int(first["dim"])
    grid = np.full((4, len(phi0s), len(seeds)), np.nan)
    for (p, s), values in rows.items():
        grid[:, phi0s.index(p), seeds.index(s)] = values
    phi, z_rel = grid[0], grid[3]
    with np.errstate(invalid="ignore", divide="ignore"):
        phi_j_rel = np.where(z_rel > d, phi / (1.0 - d / z_rel), np.nan)
    dims = ("phi0", "seed")
    return xr.Dataset(
        {"phi_soc": (dims, phi, {"long_name": "phi at the end of the SOC compression"}),
         "Z_soc": (dims, grid[1], {"long_name": "pair-collision Z of the last segment"}),
         "phi_J_soc": (dims, grid[2], {"long_name": "phi / (1 - d / Z) at the end of the SOC compression"}),
         "Z_relaxed": (dims, z_rel, {"long_name": f"Z without cells, mean of the last {RELAXED_TAIL:g} of the blocks"}),
         "phi_J_relaxed": (dims, phi_j_rel, {"long_name": "phi / (1 - d / Z_relaxed)"})},
        coords={"phi0": phi0s, "seed": seeds},
        attrs={"hardpack_kind": "glass_soc", "N": int(first["n_particles"]), "d": d, "dmu": float(first["dmu"]),
               "growth_rate": float(first["growth_rate"]), "max_pressure": float(first["max_pressure"]),
               "relax_collisions": float(relaxations[0].attrs.get("collisions", np.nan)) / int(first["n_particles"])},
    )
