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

Figures 13.16 and 13.17 of the text are built from :func:`summary_dataset`: the exponential fit of
s_c against phi_J (:func:`fit_sc_exponential`, whose parameters the text does not print) and the
maps of s_c and phi_J over the (R, nu) grid (:func:`grid_maps`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.md.compress import StopCriteria, default_window
from hardpack.md.deforming import CELL_STEP, DeformingSimulation, compress_deforming
from hardpack.md.simulation import maxwell_boltzmann

PHI_MAX = math.pi / math.sqrt(12.0)
#: phi_J of the uncorrelated labels, the MRJ state of the binary disks (Donev 2006, Fig. 13.13);
#: the reference density of the exponential fit of s_c(phi_J)
PHI_MRJ = 0.846
#: relative shortfall of the size ratio at which the growth counts as finished (round-off of the
#: kernel's A (1 + kappa t))
RATIO_TOL = 1e-12
GROWTH_FIELDS = ("time", "phi", "Z", "pressure_error", "size_ratio", "phi_J_est", "volume", "shear",
                 "collisions", "wall_time")


def start_phi(pressure: float, d: int = 2) -> float:
    """phi_max (1 - d / p): the free-volume density of the triangular crystal at reduced pressure p.

    Parameters
    ----------
    pressure : float
        Reduced pressure p, > d.
    d : int, optional
        Dimension.

    Returns
    -------
    float
        The volume fraction.
    """
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
        ``hardpack_kind`` = "microsegregated_summary" and the exponential fit of s_c against
        phi_J over all the ensembles (:func:`fit_sc_exponential`; ``sc_fit_*`` of
        :meth:`ExponentialFit.to_attrs`), whose ``sc_fit_status`` is "fitted" or says why there
        is no fit (its values are then NaN).
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
    ds = xr.Dataset(
        {"R": (dim, column("R")), "nu": (dim, column("nu")), "s_c": (dim, column("s_c")),
         "s_33": (dim, column("s_33")), "s_mix": (dim, column("s_mix")),
         "phi_J": (dim, column("phi_J")), "phi_J_err": (dim, column("phi_J", stderr)),
         "n_packings": (dim, np.array([len(groups[name]) for name in names])),
         "phi_J_est_start": (dim, column("growth_phi_J_est_start")),
         "growth_pressure_error": (dim, column("growth_pressure_error_mean"))},
        coords={"ensemble": names},
        attrs={"hardpack_kind": "microsegregated_summary", "N": sizes.pop(), "s_c_window": windows.pop(),
               "reference": "Donev 2006, sec. 13.5, Figs. 13.16-13.17"})
    ds.attrs.update(_fit_attrs(ds["phi_J"].values, ds["s_c"].values))
    return ds


def _fit_attrs(phi_j, s_c) -> dict:
    try:
        fit = fit_sc_exponential(phi_j, s_c)
    except InvalidInputError as exc:
        nan = float("nan")
        empty = ExponentialFit(nan, nan, nan, nan, nan, PHI_MRJ, len(phi_j), nan)
        return {**empty.to_attrs(), "sc_fit_status": f"not fitted: {exc}"}
    return {**fit.to_attrs(), "sc_fit_status": "fitted"}


@dataclass(frozen=True)
class ExponentialFit:
    """s_c(phi_J) = s_ref exp[-decay (phi_J - phi_ref)] fitted by :func:`fit_sc_exponential`, with
    the standard errors and the correlation of the two fitted parameters (phi_ref is fixed).

    Attributes
    ----------
    s_ref : float
        s_c at phi_ref.
    s_ref_err : float
        Its standard error.
    decay : float
        Decay rate in phi_J.
    decay_err : float
        Its standard error.
    correlation : float
        Correlation of the two fitted parameters.
    phi_ref : float
        The fixed reference density.
    n_points : int
        Ensembles fitted.
    rms_residual : float
        RMS residual of the fit.
    """

    s_ref: float
    s_ref_err: float
    decay: float
    decay_err: float
    correlation: float
    phi_ref: float
    n_points: int
    rms_residual: float

    FORM = "s_c = s_ref exp[-decay (phi_J - phi_ref)]"

    def __call__(self, phi_j):
        return self.s_ref * np.exp(-self.decay * (np.asarray(phi_j, float) - self.phi_ref))

    def to_attrs(self, prefix: str = "sc_fit_") -> dict:
        """The fit as netCDF attributes (floats and the form), keys prefixed.

        Parameters
        ----------
        prefix : str, default "sc_fit_"
            Prefix of every key.

        Returns
        -------
        dict
            ``form``, ``phi_ref``, ``s_ref``, ``s_ref_err``, ``decay``, ``decay_err``,
            ``correlation``, ``points`` (n_points) and ``rms_residual``, each with the prefix.
        """
        values = {"form": self.FORM, "phi_ref": self.phi_ref, "s_ref": self.s_ref, "s_ref_err": self.s_ref_err,
                  "decay": self.decay, "decay_err": self.decay_err, "correlation": self.correlation,
                  "points": self.n_points, "rms_residual": self.rms_residual}
        return {prefix + k: v for k, v in values.items()}

    @classmethod
    def from_attrs(cls, attrs, prefix: str = "sc_fit_"):
        """The fit stored by :meth:`to_attrs`, or None when the attributes hold no fitted values.

        Parameters
        ----------
        attrs : mapping
            Attributes, e.g. of a summary dataset.
        prefix : str, default "sc_fit_"
            Prefix of the keys.

        Returns
        -------
        ExponentialFit or None
            None when a key is missing or ``s_ref`` is not finite (a fit that failed).
        """
        keys = ("s_ref", "s_ref_err", "decay", "decay_err", "correlation", "phi_ref", "points", "rms_residual")
        if any(prefix + k not in attrs for k in keys) or not math.isfinite(float(attrs[prefix + "s_ref"])):
            return None
        values = {k: float(attrs[prefix + k]) for k in keys}
        values["n_points"] = int(values.pop("points"))
        return cls(**values)


def fit_sc_exponential(phi_j, s_c, phi_ref: float = PHI_MRJ) -> ExponentialFit:
    """Exponential fit of the configurational entropy against the jamming density (Donev 2006,
    sec. 13.5, Fig. 13.16, whose fit parameters are not printed).

    The model is s_c(phi_J) = s_ref exp[-decay (phi_J - phi_ref)]: s_ref is s_c at the fixed
    density phi_ref (default the MRJ density 0.846 of Fig. 13.13, so s_ref compares with s_mix)
    and decay = -d ln s_c / d phi_J. It is fitted by unweighted nonlinear least squares in s_c,
    started from the straight-line fit of ln s_c. The standard errors are those of the
    linearised least squares with the variance estimated from the residuals (RSS / (n - 2)): the
    scatter about the curve, whatever its source (phi_J of a few packings per ensemble, the
    sampling of s_c, a curve that is not exponential), sets them.

    Parameters
    ----------
    phi_j : array_like
        Jamming densities, one per label ensemble; finite, not all equal.
    s_c : array_like
        Configurational entropies per site of the same ensembles; finite and positive.
    phi_ref : float
        The density at which ``s_ref`` is quoted (finite).

    Returns
    -------
    ExponentialFit
        s_ref and decay with standard errors and their correlation, the number of points and the
        rms residual in s_c.

    Raises
    ------
    InvalidInputError
        Fewer than 3 points (two parameters leave no residual to estimate their errors),
        arrays of different lengths, non-finite or non-positive s_c, non-finite phi_J or all
        phi_J equal.
    """
    from scipy.optimize import curve_fit

    x = np.asarray(phi_j, dtype=float).ravel()
    y = np.asarray(s_c, dtype=float).ravel()
    if x.size != y.size:
        raise InvalidInputError(f"phi_J and s_c must have one value per ensemble each, got {x.size} and {y.size}")
    if x.size < 3:
        raise InvalidInputError(f"the exponential fit has two parameters and needs at least 3 points for their "
                                f"standard errors, got {x.size}; run more label ensembles (R, nu)")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y)) and math.isfinite(phi_ref)):
        raise InvalidInputError(f"phi_J, s_c and phi_ref must be finite, got phi_J = {x.tolist()}, "
                                f"s_c = {y.tolist()}, phi_ref = {phi_ref!r}")
    if not np.all(y > 0):
        raise InvalidInputError(f"s_c must be positive (an entropy per site of labels with both species), "
                                f"got {y.tolist()}")
    dx = x - phi_ref
    if np.ptp(dx) == 0:
        raise InvalidInputError(f"all phi_J equal {x[0]!r}: the decay of s_c with phi_J is undetermined")
    slope, intercept = np.polyfit(dx, np.log(y), 1)

    def model(u, s_ref, decay):
        return s_ref * np.exp(-decay * u)

    params, cov = curve_fit(model, dx, y, p0=(math.exp(intercept), -slope))
    residual = y - model(dx, *params)
    err = np.sqrt(np.diag(cov))
    corr = float(cov[0, 1] / (err[0] * err[1])) if np.all(err > 0) else float("nan")
    return ExponentialFit(s_ref=float(params[0]), s_ref_err=float(err[0]), decay=float(params[1]),
                          decay_err=float(err[1]), correlation=corr, phi_ref=float(phi_ref), n_points=int(x.size),
                          rms_residual=float(np.sqrt(np.mean(residual ** 2))))


def _grid_values(name: str, values) -> np.ndarray:
    v = np.asarray(values, dtype=float).ravel()
    if v.size == 0 or not np.all(np.isfinite(v)):
        raise InvalidInputError(f"the grid's {name} values must be a non-empty list of finite numbers, got {values!r}")
    if np.unique(v).size != v.size:
        raise InvalidInputError(f"the grid's {name} values must not repeat, got {v.tolist()}")
    return v


def grid_maps(summary: xr.Dataset, r_values, nu_values) -> xr.Dataset:
    """s_c(R, nu) and phi_J(R, nu) of the label ensembles on a grid of Matérn parameters (Donev
    2006, Fig. 13.17).

    Parameters
    ----------
    summary : xarray.Dataset
        A ``microsegregated_summary`` dataset (:func:`summary_dataset`).
    r_values, nu_values : sequence of float
        The grid's correlation lengths R and smoothness parameters nu, in the order to show them
        (the config's lists); finite, no repeats.

    Returns
    -------
    xarray.Dataset
        Along ``R`` and ``nu`` (the given values): ``s_c``, ``phi_J`` (mean over the packings),
        ``phi_J_err``, ``n_packings`` and ``ensemble``. A cell without an ensemble is missing:
        NaN values, 0 packings, ensemble "". Attributes: ``N``, ``s_c_window`` and
        ``reference`` of the summary, ``hardpack_kind`` = "microsegregated_maps",
        ``missing_cells`` and ``off_grid`` (the ensembles off the grid, e.g. "random", comma
        separated).

    Raises
    ------
    InvalidInputError
        Not a summary, a bad grid, or two ensembles with the same (R, nu).
    """
    if summary.attrs.get("hardpack_kind") != "microsegregated_summary":
        raise InvalidInputError("expected a microsegregated_summary dataset (hardpack glass-microsegregated-summary)")
    r_grid, nu_grid = _grid_values("R", r_values), _grid_values("nu", nu_values)
    shape = (r_grid.size, nu_grid.size)
    columns = {"s_c": np.full(shape, np.nan), "phi_J": np.full(shape, np.nan), "phi_J_err": np.full(shape, np.nan)}
    n_packings = np.zeros(shape, dtype=int)
    ensemble = np.full(shape, "", dtype=object)
    off_grid = []
    for k, name in enumerate(summary["ensemble"].values):
        rows = np.flatnonzero(np.isclose(r_grid, float(summary["R"].values[k]), rtol=1e-9, atol=0.0))
        cols = np.flatnonzero(np.isclose(nu_grid, float(summary["nu"].values[k]), rtol=1e-9, atol=0.0))
        if rows.size == 0 or cols.size == 0:
            off_grid.append(str(name))
            continue
        i, j = rows[0], cols[0]
        if ensemble[i, j]:
            raise InvalidInputError(f"ensembles {ensemble[i, j]!r} and {str(name)!r} have the same "
                                    f"(R, nu) = ({r_grid[i]:g}, {nu_grid[j]:g})")
        ensemble[i, j] = str(name)
        n_packings[i, j] = int(summary["n_packings"].values[k])
        for key, grid in columns.items():
            grid[i, j] = float(summary[key].values[k])
    dims = ("R", "nu")
    data = {key: (dims, grid) for key, grid in columns.items()}
    data.update(n_packings=(dims, n_packings), ensemble=(dims, ensemble.astype(str)))
    attrs = {key: summary.attrs[key] for key in ("N", "s_c_window", "reference")}
    attrs.update(hardpack_kind="microsegregated_maps", missing_cells=int((n_packings == 0).sum()),
                 off_grid=",".join(off_grid))
    return xr.Dataset(data, coords={"R": r_grid, "nu": nu_grid}, attrs=attrs)
