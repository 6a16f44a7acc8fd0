"""Micro-segregated binary disk packings (Donev 2006, sec. 13.5, Figs. 13.13-13.17).

Protocol of the text: a monodisperse triangular crystal at reduced pressure p = 100 whose sites
carry the A / B labels of a level-cut Gaussian random field (:mod:`hardpack.glass.segregated`);
the B (large) disks grow slowly (gamma = 1e-5 in Fig. 13.14) while a Parrinello-Rahman-like
constant-pressure MD keeps p ~ 100, until the diameter ratio reaches kappa = 1.4; then the packing
is compressed slowly to jamming. phi_J is reported against the labels' configurational entropy
s_c ~ s_{4,4} (Fig. 13.16).

Choices made here (the text does not fix them):

- the start crystal is at the free-volume density of the pressure, phi_0 = phi_max (1 - d / p)
  (the inverse of Eq. 1.1 of Donev 2006, ch. 1, phi_max = pi / sqrt(12)); the barostat corrects
  what the free-volume estimate misses;
- "keeping the pressure at p ~ 100" is read as the reduced pressure p = P V / (N kT) of the whole
  chapter (sec. 13.2) held at the target: before every window the applied pressure of the
  deforming-cell MD (:class:`hardpack.md.deforming.DeformingSimulation`, Donev 2006, sec. 3.2.4.2)
  is set to P0 = p N kT / V for the current volume V (kT = 1, the velocities are rescaled every
  window). A fixed P0 in absolute units would let p rise with the area of the B disks, by a
  factor (x_A + x_B kappa^2) = 1.32 at kappa = 1.4;
- the growing B disks have dD/dt = gamma each, the A disks keep their size exactly;
- the compression to jamming is the deforming-cell LS compression
  (:func:`hardpack.md.deforming.compress_deforming`, uniform growth, shape relaxed at fixed
  volume) to a reduced pressure ``max_pressure``; phi_J is the final volume fraction and
  ``phi_J_est`` = phi / (1 - d / p) of its last window.
"""

from __future__ import annotations

import math
import time

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.md.compress import StopCriteria, default_window
from hardpack.md.deforming import CELL_STEP, DeformingSimulation, compress_deforming
from hardpack.md.simulation import maxwell_boltzmann

PHI_MAX = math.pi / math.sqrt(12.0)
#: relative shortfall of the size ratio at which the growth counts as finished (round-off of the
#: kernel's A (1 + kappa t))
RATIO_TOL = 1e-12
GROWTH_FIELDS = ("time", "phi", "Z", "pressure_error", "size_ratio", "phi_J_est", "volume", "shear",
                 "collisions", "wall_time")


def start_phi(pressure: float, d: int = 2) -> float:
    """phi_max (1 - d / p): the free-volume density of the triangular crystal at reduced pressure p."""
    if not (math.isfinite(pressure) and pressure > d):
        raise InvalidInputError(f"the reduced pressure must be a finite number > {d}, got {pressure!r}")
    return PHI_MAX * (1.0 - d / pressure)


def _check_growth(packing: Packing, species: int, ratio: float, pressure: float, growth_rate: float) -> np.ndarray:
    if packing.species is None:
        raise InvalidInputError("the packing carries no species labels; start from a labelled crystal "
                                "(hardpack.glass.segregated.labelled_crystal)")
    growing = np.asarray(packing.species) == species
    if not growing.any() or growing.all():
        raise InvalidInputError(f"species {species} must label some but not all particles "
                                f"({int(growing.sum())} of {packing.n_particles} do)")
    fixed = packing.radii[~growing]
    if not np.all(fixed == fixed[0]) or not np.all(packing.radii[growing] == packing.radii[growing][0]):
        raise InvalidInputError("each species must have one radius before the growth")
    if not (math.isfinite(ratio) and ratio > packing.radii[growing][0] / fixed[0]):
        raise InvalidInputError(f"the target diameter ratio {ratio!r} must be finite and above the current "
                                f"{packing.radii[growing][0] / fixed[0]:.6g}")
    if not (math.isfinite(pressure) and pressure > packing.dim):
        raise InvalidInputError(f"the reduced pressure must be a finite number > {packing.dim}, got {pressure!r}")
    if isinstance(growth_rate, bool) or not (math.isfinite(growth_rate) and growth_rate > 0):
        raise InvalidInputError(f"growth_rate must be a finite positive number, got {growth_rate!r}")
    return growing


def grow_species(packing: Packing, species: int, ratio: float, pressure: float, growth_rate: float, seed: int,
                 *, cell_step: float = CELL_STEP, window: float | None = None,
                 progress=None) -> tuple[Packing, xr.Dataset, dict]:
    """Grow the particles of one species at constant reduced pressure until their diameter is
    ``ratio`` times the others' (Donev 2006, sec. 13.5, Fig. 13.14; module docstring).

    Parameters
    ----------
    packing : Packing
        Periodic disk (or sphere) packing with ``species``; each species of one radius.
    species : int
        The label of the growing particles (1 = B in :mod:`hardpack.glass.segregated`).
    ratio : float
        Target diameter ratio kappa (1.4 in the text), above the current one.
    pressure : float
        Reduced pressure p = P V / (N kT) held during the growth (100 in the text), > d.
    growth_rate : float
        dD/dt of each growing particle in units sqrt(kT / m) (gamma = 1e-5 in Fig. 13.14).
    seed : int
        Seed of the Maxwell-Boltzmann start velocities.
    cell_step : float
        alpha of the deforming cell's strain rule.
    window : float, optional
        Collisions per particle per window; default :func:`hardpack.md.default_window`.
    progress : callable, optional
        Receives each window's record.

    Returns
    -------
    tuple
        (the grown packing, the per-window time series with ``size_ratio``, ``Z``,
        ``pressure_error`` = Z / p - 1 and ``phi_J_est`` = phi / (1 - d / Z), stats with the
        time-weighted mean and rms of ``pressure_error``).
    """
    growing = _check_growth(packing, species, ratio, pressure, growth_rate)
    n, d = packing.n_particles, packing.dim
    sim = DeformingSimulation(packing, maxwell_boltzmann(n, d, seed), float(growth_rate),
                              applied_pressure=pressure * n / abs(float(np.linalg.det(packing.lattice))),
                              cell_step=cell_step, growing=growing)
    a_fixed = float(packing.radii[~growing][0])
    target = ratio * a_fixed
    per_particle = default_window(growth_rate, d) if window is None else float(window)
    records = {k: [] for k in GROWTH_FIELDS}
    started = time.perf_counter()
    while (a_grow := float(sim.A[growing][0])) < target * (1.0 - RATIO_TOL):
        sim.applied_pressure = pressure * n / sim.volume
        rec = sim.run_window(max(1, round(per_particle * n)), max_time=2.0 * (target - a_grow) / growth_rate)
        z = rec["Z"]
        rec.update(size_ratio=float(sim.A[growing][0]) / a_fixed, pressure_error=z / pressure - 1.0,
                   phi_J_est=rec["phi"] / (1.0 - d / z) if z > d else float("nan"))
        for k in GROWTH_FIELDS:
            records[k].append(rec[k])
        if progress is not None:
            progress(rec)
    final = sim.packing()
    report = final.overlap_report()
    errors = np.asarray(records["pressure_error"])
    durations = np.diff(np.concatenate([[0.0], records["time"]]))  # weights: a last, short window counts little
    stats = {"growth_protocol": "species growth at constant reduced pressure (deforming cell)",
             "growth_species": int(species), "growth_ratio": float(final.radii[growing][0] / a_fixed),
             "growth_pressure": float(pressure), "growth_gamma": float(growth_rate), "growth_seed": int(seed),
             "growth_collisions": int(sim.collisions), "growth_windows": int(sim.windows),
             "growth_wall_time": time.perf_counter() - started, "growth_phi_end": float(final.phi),
             "growth_pressure_error_mean": float(np.average(errors, weights=durations)),
             "growth_pressure_error_rms": float(np.sqrt(np.average(errors ** 2, weights=durations))),
             "growth_phi_J_est_start": float(records["phi_J_est"][0]),
             "growth_overlap_check": "passed" if report.n_overlapping == 0 else "failed"}
    if report.n_overlapping:
        raise RuntimeError(f"the grown packing overlaps ({report}): an engine failure")
    desc = {"size_ratio": "diameter of the growing species / the others' at the window end",
            "Z": "reduced pressure pV/(NkT) over the window", "pressure_error": "Z / p_target - 1",
            "phi_J_est": "phi / (1 - d / Z) (Donev 2006, Eq. 1.2)"}
    ts = xr.Dataset({k: ("window", np.asarray(records[k], dtype=float), {"description": desc.get(k, k)})
                     for k in GROWTH_FIELDS}, coords={"window": np.arange(len(records["time"]))})
    ts.attrs.update({"hardpack_kind": "md_timeseries", "N": n, "d": d, "seed": int(seed),
                     "growth_rate": float(growth_rate), "target_pressure": float(pressure),
                     "target_ratio": float(ratio), "reference": "Donev 2006, sec. 13.5, Fig. 13.14"})
    return final, ts, stats


def microsegregated_packing(labels: xr.Dataset, realisation: int = 0, *, ensemble: str = "", ratio: float = 1.4,
                            pressure: float = 100.0,
                            growth_rate: float = 1e-5, compress_rate: float = 1e-5, max_pressure: float = 1e12,
                            seed: int = 0, cell_step: float = CELL_STEP, progress=None):
    """Labelled crystal -> B growth at constant pressure -> LS compression to jamming (Donev 2006,
    sec. 13.5; module docstring).

    Parameters
    ----------
    labels : xarray.Dataset
        A ``glass_labels`` dataset (:func:`hardpack.glass.segregated.label_study`); its pooled
        window entropy at the largest window is s_c.
    realisation : int
        Which label realisation labels the crystal.
    ensemble : str
        Name of the label ensemble (stored; the summary groups by it; "random" marks the
        uncorrelated labels of the MRJ reference).
    ratio, pressure, growth_rate : float
        Target diameter ratio, reduced pressure and dD/dt of the B disks during the growth.
    compress_rate : float
        Gamma of the LS compression to jamming.
    max_pressure : float
        Reduced pressure that ends the compression (jamming).
    seed : int
        Seed of the start velocities of both stages.
    cell_step : float
        alpha of the deforming cell.
    progress : callable, optional
        Receives each window's record of both stages.

    Returns
    -------
    tuple
        (:class:`hardpack.md.compress.CompressResult` of the compression, with the growth's and
        the labels' numbers in its ``stats``: ``phi_J``, ``s_c``, ``s_c_window``, ``s_33``,
        ``s_mix``, ``R``, ``nu``; the growth time series).
    """
    from hardpack.glass.segregated import LABEL_B, labelled_crystal

    if labels.attrs.get("hardpack_kind") != "glass_labels":
        raise InvalidInputError("labels must be a glass_labels dataset (hardpack glass-labels)")
    k = labels.sizes["realisation"]
    if isinstance(realisation, bool) or not 0 <= int(realisation) < k:
        raise InvalidInputError(f"realisation must be in 0..{k - 1}, got {realisation!r}")
    for name, value in (("compress_rate", compress_rate), ("max_pressure", max_pressure)):
        if isinstance(value, bool) or not (math.isfinite(value) and value > 0):
            raise InvalidInputError(f"{name} must be a finite positive number, got {value!r}")
    crystal = labelled_crystal(labels["labels"].values[int(realisation)], start_phi(pressure))
    grown, growth_ts, growth_stats = grow_species(crystal, LABEL_B, ratio, pressure, growth_rate, seed,
                                                  cell_step=cell_step, progress=progress)
    result = compress_deforming(grown, compress_rate, seed, StopCriteria(max_pressure=max_pressure),
                                cell_step=cell_step, progress=progress)
    s = labels["entropy_per_site"].values
    rows, cols = labels["entropy_per_site"].shape
    result.stats.update(growth_stats)
    result.stats.update({
        "compression_protocol": result.stats["protocol"],
        "protocol": "microsegregated (Donev 2006, sec. 13.5)", "phi_J": float(result.packing.phi),
        "s_c": float(s[-1, -1]), "s_c_window": f"{rows}x{cols}",
        "s_33": float(s[2, 2]) if min(rows, cols) >= 3 else float("nan"),
        "s_mix": float(labels.attrs["s_mix"]), "R": float(labels.attrs["R"]), "nu": float(labels.attrs["nu"]),
        "ensemble": str(ensemble), "N": int(result.packing.n_particles),
        "label_realisation": int(realisation), "label_realisations": int(k),
        "label_seed": int(labels.attrs.get("seed", -1)), "start_phi": float(crystal.phi),
        "compress_rate": float(compress_rate), "max_pressure": float(max_pressure),
    })
    return result, growth_ts


def summary_dataset(packings) -> xr.Dataset:
    """phi_J and s_c of each label ensemble (Donev 2006, Figs. 13.16-13.17) from the jammed packings
    of :func:`microsegregated_packing`.

    Parameters
    ----------
    packings : iterable of xarray.Dataset
        Packing datasets whose attributes carry ``ensemble``, ``R``, ``nu``, ``phi_J``, ``s_c``.

    Returns
    -------
    xarray.Dataset
        Along ``ensemble`` (sorted by name): ``R``, ``nu``, ``s_c``, ``s_33``, ``s_mix``,
        ``phi_J`` (mean over the ensemble's packings), ``phi_J_err`` (standard error; NaN for one
        packing), ``n_packings``, ``phi_J_est_start`` (mean phi~_J at the start of the growth,
        Fig. 13.14), ``growth_pressure_error`` (mean); attributes ``N``, ``s_c_window``,
        ``hardpack_kind`` = "microsegregated_summary".
    """
    groups: dict[str, list] = {}
    for ds in packings:
        if "phi_J" not in ds.attrs or "ensemble" not in ds.attrs:
            raise InvalidInputError("expected packings of hardpack glass-microsegregated (attributes phi_J, ensemble)")
        groups.setdefault(str(ds.attrs["ensemble"]), []).append(ds.attrs)
    if not groups:
        raise InvalidInputError("no packings to summarise")
    names = sorted(groups)
    sizes = {int(a["N"]) for g in groups.values() for a in g}
    windows = {str(a["s_c_window"]) for g in groups.values() for a in g}
    if len(sizes) != 1 or len(windows) != 1:
        raise InvalidInputError(f"the packings mix sizes {sorted(sizes)} or s_c windows {sorted(windows)}")

    def column(key, reduce=np.mean):
        return np.array([reduce([float(a[key]) for a in groups[name]]) for name in names])

    def stderr(values):
        return float(np.std(values, ddof=1) / np.sqrt(len(values))) if len(values) > 1 else float("nan")

    for name in names:
        if len({(float(a["R"]), float(a["nu"]), float(a["s_c"])) for a in groups[name]}) != 1:
            raise InvalidInputError(f"ensemble {name!r} mixes label parameters or label statistics")
    dim = ("ensemble",)
    return xr.Dataset(
        {"R": (dim, column("R")), "nu": (dim, column("nu")), "s_c": (dim, column("s_c")),
         "s_33": (dim, column("s_33")), "s_mix": (dim, column("s_mix")),
         "phi_J": (dim, column("phi_J")), "phi_J_err": (dim, column("phi_J", stderr)),
         "n_packings": (dim, np.array([len(groups[name]) for name in names])),
         "phi_J_est_start": (dim, column("growth_phi_J_est_start")),
         "growth_pressure_error": (dim, column("growth_pressure_error_mean"))},
        coords={"ensemble": names},
        attrs={"hardpack_kind": "microsegregated_summary", "N": sizes.pop(), "s_c_window": windows.pop(),
               "reference": "Donev 2006, sec. 13.5, Figs. 13.16-13.17"})
