"""The binary hard-disk glass study (Donev 2006, ch. 13; Donev, Stillinger & Torquato 2006): the
triangular start crystal, the EOS of compressions binned in phi, and the summaries of the
pipeline (EOS with fits and free energies; configurational entropy of the SOC glasses).

EOS from compressions (sec. 13.3): every window of an LS compression (or decompression) gives
its phi (the window's mid point) and Z; windows are binned in phi (``bin_width``), each run gives
the mean Z per bin, and the runs of one growth rate are averaged with the standard error over
runs (or, with one run, over its windows in the bin: then the windows' correlation makes the
error an underestimate, recorded as ``z_err_kind``).
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr
from scipy.optimize import brentq

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.glass import fits, thermo

PHI_TRIANGULAR = math.pi / math.sqrt(12.0)
#: bootstrap replicas of the freezing point's standard errors (:func:`freezing_dataset`) and their seed
FREEZING_REPLICAS, FREEZING_SEED = 100, 20061
#: the monodisperse transition density at which a phase of the separated crystal melts: the middle of
#: the transition region 0.70-0.72 (Donev 2006, sec. 13.1), and the overall densities of its curves
SEPARATED_TRANSITION, SEPARATED_TRANSITION_SPAN = 0.71, (0.70, 0.72)
SEPARATED_PHI = np.round(np.arange(0.60, 0.8801, 0.0025), 4)


def triangular_crystal(nx: int, ny: int, phi: float) -> Packing:
    """Monodisperse triangular crystal of 2 nx ny disks in an orthorhombic periodic box (the
    2-disk rectangular cell a x a sqrt(3)), radii scaled to volume fraction ``phi``.

    Parameters
    ----------
    nx, ny : int
        Rectangular cells along x and y (>= 1; nx = 2 ny gives a nearly square box).
    phi : float
        Volume fraction in (0, pi / sqrt(12)).

    Returns
    -------
    Packing
        The crystal.

    Raises
    ------
    InvalidInputError
        For nx or ny below 1, or phi outside (0, pi / sqrt(12)).
    """
    if nx < 1 or ny < 1:
        raise InvalidInputError(f"nx and ny must be >= 1, got {nx}, {ny}")
    if not 0 < phi < PHI_TRIANGULAR:
        raise InvalidInputError(f"phi must be in (0, {PHI_TRIANGULAR:.6f}) (close packing), got {phi}")
    s3 = math.sqrt(3.0)
    basis = np.array([[0.0, 0.0], [0.5, s3 / 2]])
    ix, iy = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    origins = np.column_stack([ix.ravel(), s3 * iy.ravel()])
    positions = (origins[:, None, :] + basis[None, :, :]).reshape(-1, 2) + 0.25
    radius = 0.5 * math.sqrt(phi / PHI_TRIANGULAR)
    return Packing(positions, np.full(len(positions), radius), np.diag([nx, s3 * ny]))


def phase_separated_crystal(columns: tuple[int, int], rows: tuple[int, int], kappa: float, phi: float) -> Packing:
    """A fully phase-separated binary crystal (Donev 2006, sec. 13.2.2.1, the start of Fig. 13.5):
    a slab of small disks A (diameter 1) and a slab of large disks B (diameter kappa), each a
    triangular crystal with rows along x, stacked along y in an orthorhombic periodic box.

    Both slabs span the box along x, so the lattice spacings satisfy c_A a_A = c_B a_B; with
    c_A / c_B = kappa both slabs are scaled copies at the same density (at kappa = 1.4: 7 k and 5 k
    columns; 10 j and 7 j rows give x_B = 1/3). The interface rows are set apart by the larger of
    the two half row spacings and 1.0001 (r_A + r_B): the lattices do not match across the
    interface, so a disk may sit right above one of the other slab. The disks then grow until the
    overall density is ``phi``.

    Parameters
    ----------
    columns, rows : (int, int)
        Columns and rows (even) of the A and the B slab.
    kappa : float
        Diameter ratio B / A, >= 1.
    phi : float
        Overall volume fraction; at most the density at which the slabs are close packed.

    Returns
    -------
    Packing
        c_A r_A + c_B r_B disks, ``species`` 0 (A) and 1 (B).

    Raises
    ------
    InvalidInputError
        For counts below 1, odd rows, kappa < 1, or phi outside (0, its largest value).
    """
    (c_a, c_b), (r_a, r_b) = (int(c) for c in columns), (int(r) for r in rows)
    if min(c_a, c_b, r_a, r_b) < 1 or r_a % 2 or r_b % 2:
        raise InvalidInputError(f"columns must be >= 1 and rows even and >= 2, got {columns}, {rows}")
    if not kappa >= 1.0:
        raise InvalidInputError(f"kappa must be >= 1, got {kappa}")
    s3 = math.sqrt(3.0)
    a_a, a_b = 1.0, c_a / c_b
    h_a, h_b = s3 / 2 * a_a, s3 / 2 * a_b
    n_a, n_b = c_a * r_a, c_b * r_b

    def layout(touch: float):
        """Positions, radii and box for A disks of diameter ``touch`` a_A."""
        rad_a, rad_b = touch / 2, kappa * touch / 2
        gap = max((h_a + h_b) / 2, 1.0001 * (rad_a + rad_b))
        y_b0 = (r_a - 1) * h_a + gap
        height = y_b0 + (r_b - 1) * h_b + gap
        ia, ja = np.meshgrid(np.arange(c_a), np.arange(r_a), indexing="ij")
        ib, jb = np.meshgrid(np.arange(c_b), np.arange(r_b), indexing="ij")
        pos_a = np.column_stack([(ia + 0.5 * (ja % 2)).ravel() * a_a, ja.ravel() * h_a])
        pos_b = np.column_stack([(ib + 0.5 * (jb % 2)).ravel() * a_b, y_b0 + jb.ravel() * h_b])
        positions = np.vstack([pos_a, pos_b]) + 0.25
        radii = np.concatenate([np.full(n_a, rad_a), np.full(n_b, rad_b)])
        return positions, radii, np.diag([c_a * a_a, height])

    def density(touch):
        _, radii, box = layout(touch)
        return float(np.pi * np.sum(radii**2) / (box[0, 0] * box[1, 1]))

    largest = min(1.0, a_b / kappa)   # the A (or B) rows touch
    top = density(largest)
    if not 0 < phi <= top:
        raise InvalidInputError(f"phi must be in (0, {top:.6f}] (the slabs close packed), got {phi}")
    touch = brentq(lambda t: density(t) - phi, 1e-9, largest, xtol=1e-15)
    positions, radii, box = layout(touch)
    return Packing(positions, radii, box, species=np.repeat([0, 1], [n_a, n_b]))


def window_points(ts: xr.Dataset) -> tuple[np.ndarray, np.ndarray]:
    """(phi at each window's mid point, Z of the window) of an MD time series.

    Parameters
    ----------
    ts : xarray.Dataset
        MD time series (variables phi and Z over ``window``).

    Returns
    -------
    phi : numpy.ndarray of float, shape (n_windows,)
        Mid-window volume fractions.
    z : numpy.ndarray of float, shape (n_windows,)
        Reduced pressures.
    """
    phi_end = ts["phi"].values
    start = float(ts.attrs.get("phi_start", phi_end[0]))
    phi_start = np.concatenate([[start], phi_end[:-1]])
    return 0.5 * (phi_start + phi_end), ts["Z"].values


def continued_run(series: list[xr.Dataset], parent: list[xr.Dataset], *,
                  tol: float = 1e-6) -> tuple[list[xr.Dataset], float]:
    """One run of a compression that continues another from one of its stages: the parent's time
    series up to where the continuation starts, then the continuation's, so that its EOS integral
    starts at low density (the slow branch of the pipeline, started from the equilibrium liquid of
    a faster compression).

    Parameters
    ----------
    series : list of xarray.Dataset
        The continuation's time series (one run, any order).
    parent : list of xarray.Dataset
        The parent compression's time series of the same seed (any order).
    tol : float, default 1e-6
        How far the parent's last phi before the continuation may be from its start (the
        ``phi_start`` attribute; without it, the start of the first window extrapolated from the
        first two, and the tolerance widened by one window).

    Returns
    -------
    run : list of xarray.Dataset
        The parent's series that end at or before the continuation's start, then the continuation's,
        in order of phi.
    start : float
        The volume fraction where the continuation starts (the parent's end there).

    Raises
    ------
    InvalidInputError
        When no parent series ends where the continuation starts.
    """
    def first(ts):
        return float(ts["phi"].values[0])

    series = sorted(series, key=first)
    phi = series[0]["phi"].values
    if "phi_start" in series[0].attrs:
        start = float(series[0].attrs["phi_start"])
    else:
        width = phi[1] - phi[0] if phi.size > 1 else 0.0
        start, tol = phi[0] - width, tol + width
    prefix = sorted((ts for ts in parent if float(ts["phi"].values[-1]) <= phi[0] + tol), key=first)
    if not prefix or abs(float(prefix[-1]["phi"].values[-1]) - start) > tol:
        ends = sorted(round(float(ts["phi"].values[-1]), 6) for ts in parent)
        raise InvalidInputError(f"the continued compression starts at phi = {start:.6f}, where no stage of its "
                                f"parent ends (parent stages end at {ends}); give the parent's time series of "
                                f"the same seed up to that snapshot")
    return prefix + series, float(prefix[-1]["phi"].values[-1])


def bin_runs(runs: list[list[xr.Dataset]], edges: np.ndarray) -> dict[str, np.ndarray]:
    """Mean Z per phi bin of each run (a run: its time series, e.g. consecutive segments), then
    the mean and standard error over runs (module docstring).

    Parameters
    ----------
    runs : list of list of xarray.Dataset
        Per run, its MD time series in order.
    edges : numpy.ndarray of float, shape (nb + 1,)
        phi bin edges.

    Returns
    -------
    dict
        ``phi`` (mean phi of the windows in each bin, over runs), ``Z``, ``Z_err``, ``n_runs``,
        ``n_windows`` per bin; ``err_from_windows`` (bool) when only one run had the bin.
    """
    nb = edges.size - 1
    per_run_z = np.full((len(runs), nb), np.nan)
    per_run_phi = np.full((len(runs), nb), np.nan)
    var_win = np.full((len(runs), nb), np.nan)
    n_win = np.zeros(nb, int)
    for r, series in enumerate(runs):
        phi = np.concatenate([window_points(ts)[0] for ts in series]) if series else np.zeros(0)
        z = np.concatenate([window_points(ts)[1] for ts in series]) if series else np.zeros(0)
        keep = np.isfinite(phi) & np.isfinite(z)
        idx = np.digitize(phi[keep], edges) - 1
        for b in range(nb):
            sel = idx == b
            k = int(sel.sum())
            if k:
                per_run_z[r, b] = z[keep][sel].mean()
                per_run_phi[r, b] = phi[keep][sel].mean()
                var_win[r, b] = z[keep][sel].var(ddof=1) / k if k > 1 else np.nan
                n_win[b] += k
    n_runs = np.sum(np.isfinite(per_run_z), axis=0)
    with np.errstate(invalid="ignore", divide="ignore"), _quiet():
        z_mean = np.nanmean(per_run_z, axis=0)
        phi_mean = np.nanmean(per_run_phi, axis=0)
        z_err = np.nanstd(per_run_z, axis=0, ddof=1) / np.sqrt(n_runs)
        single = n_runs == 1
        z_err[single] = np.sqrt(np.nanmax(var_win, axis=0)[single])
    return {"phi": phi_mean, "Z": z_mean, "Z_err": z_err, "n_runs": n_runs, "n_windows": n_win,
            "err_from_windows": single}


class _quiet:
    def __enter__(self):
        import warnings

        self._w = warnings.catch_warnings()
        self._w.__enter__()
        warnings.simplefilter("ignore", RuntimeWarning)

    def __exit__(self, *exc):
        self._w.__exit__(*exc)


def eos_dataset(branches: dict, edges: np.ndarray, *, d: int = 2, slope0: float = 2.0,
                liquid_range=(0.70, 0.80), glass_range=(0.80, 0.84), starts: dict | None = None,
                attrs: dict | None = None) -> xr.Dataset:
    """The EOS summary of one system: Z(phi) per branch (growth rate, or "decompression") with
    phi~_J, the excess free energy Delta f(phi) integrated from the ideal gas along each
    compression branch, and the fits of Eq. 13.3 (to the slowest compression) and Eq. 13.4
    (to each compression branch), with their coefficient errors.

    Parameters
    ----------
    branches : dict
        Branch name -> list of runs, a run being the list of its time-series Datasets in order.
        Names of compressions are their growth rates as strings ("1e-05"); other names (e.g.
        "decompression") are binned but get no free energy (they do not start at low density).
    edges : numpy.ndarray
        phi bin edges.
    d : int, default 2
        Dimension (the free-volume prefactor of phi~_J).
    slope0 : float, default 2.0
        (Z - 1)/phi at phi = 0 (:func:`hardpack.glass.thermo.second_virial_slope`).
    liquid_range, glass_range : (float, float)
        phi ranges of the Eq. 13.3 and Eq. 13.4 fits (Eq. 13.3 stops earlier where the slowest
        compression and the next faster one separate, :func:`_add_fits`).
    starts : dict, optional
        Branch name -> the phi where a compression that continues another starts (its runs hold
        the parent's series below it, :func:`continued_run`); stored as ``start_phi`` (NaN for the
        other branches).
    attrs : dict, optional
        Attributes to add (system, kappa, x_large, N, ...).

    Returns
    -------
    xarray.Dataset
        The EOS summary over (branch, phi bin centre), kind ``glass_eos``, fits as attributes.
    """
    names = list(branches)
    if not names:
        raise InvalidInputError("no EOS branches given")
    centres = 0.5 * (edges[1:] + edges[:-1])
    vars_ = {k: np.full((len(names), centres.size), np.nan)
             for k in ("phi_mean", "Z", "Z_err", "phij", "phij_err", "excess", "excess_err")}
    n_runs = np.zeros((len(names), centres.size), int)
    rates = []
    for b, name in enumerate(names):
        res = bin_runs(branches[name], edges)
        vars_["phi_mean"][b], vars_["Z"][b], vars_["Z_err"][b] = res["phi"], res["Z"], res["Z_err"]
        n_runs[b] = res["n_runs"]
        vars_["phij"][b], vars_["phij_err"][b] = fits.estimated_jamming_density(res["phi"], res["Z"], res["Z_err"], d)
        try:
            rate = float(name)
        except ValueError:
            rate = math.nan
        rates.append(rate)
        ok = np.flatnonzero(np.isfinite(res["Z"]))
        if math.isfinite(rate) and rate > 0 and ok.size:
            # a compression from low density: the trapezoid integral over the non-empty bins
            span = ok
            f, fe = thermo.excess_free_energy(res["phi"][span], res["Z"][span], res["Z_err"][span], slope0=slope0)
            vars_["excess"][b, span], vars_["excess_err"][b, span] = f, fe
    ds = xr.Dataset(
        {k: (("branch", "phi"), v) for k, v in vars_.items()} | {"n_runs": (("branch", "phi"), n_runs)},
        coords={"branch": names, "phi": centres, "growth_rate": ("branch", np.array(rates)),
                "start_phi": ("branch", np.array([(starts or {}).get(b, math.nan) for b in names], float))},
    )
    ds.attrs.update({"hardpack_kind": "glass_eos", "bin_width": float(edges[1] - edges[0]), "d": d,
                     "slope0": slope0, **(attrs or {})})
    _add_fits(ds, liquid_range, glass_range)
    return ds


def _add_fits(ds: xr.Dataset, liquid_range, glass_range) -> None:
    """Eq. 13.3 to the slowest compression, Eq. 13.4 to every compression (NaN where too few
    points); coefficients and errors as variables, the ranges as attributes.

    The cubic is fitted over ``liquid_range`` up to where the slowest compression and the next
    faster one separate (:func:`hardpack.glass.fits.equilibrium_limit`, the text's rule; stored as
    ``liquid_fit_max``)."""
    rates = ds["growth_rate"].values
    comp = np.flatnonzero(np.isfinite(rates) & (rates > 0))
    cubic = np.full(4, np.nan)
    cubic_err = np.full(4, np.nan)
    fit_max = float(liquid_range[1])
    if comp.size:
        slow = comp[np.argmin(rates[comp])]
        row = ds.isel(branch=slow)
        phi, pj, pe = row["phi_mean"].values, row["phij"].values, row["phij_err"].values
        faster = comp[rates[comp] > rates[slow]]
        if faster.size:
            other = ds.isel(branch=faster[np.argmin(rates[faster])])
            fit_max = fits.equilibrium_limit(ds["phi"].values, pj, pe, other["phij"].values,
                                             other["phij_err"].values, fit_max)
            ds.attrs["liquid_fit_compared"] = str(other["branch"].values)
        sel = (phi >= liquid_range[0]) & (ds["phi"].values <= fit_max) & np.isfinite(pj)
        if sel.sum() > 4:
            fit = fits.fit_liquid_cubic(phi[sel], pj[sel], pe[sel], phi_max=liquid_range[1])
            cubic, cubic_err = fit.coefficients, fit.errors
        ds.attrs["cubic_branch"] = str(ds["branch"].values[slow])
    ds.attrs["liquid_fit_max"] = fit_max
    ds["cubic"] = ("power", cubic)
    ds["cubic_err"] = ("power", cubic_err)
    alpha = np.full(rates.size, np.nan)
    alpha_err, phi_j, phi_j_err = alpha.copy(), alpha.copy(), alpha.copy()
    for b in comp:
        row = ds.isel(branch=b)
        phi, pj, pe = row["phi_mean"].values, row["phij"].values, row["phij_err"].values
        sel = (phi >= glass_range[0]) & (phi <= glass_range[1]) & np.isfinite(pj)
        if sel.sum() > 2:
            try:
                g = fits.fit_glass_branch(phi[sel], pj[sel], pe[sel], phi_min=glass_range[0])
            except InvalidInputError:
                continue
            alpha[b], alpha_err[b], phi_j[b], phi_j_err[b] = g.alpha, g.alpha_err, g.phi_j, g.phi_j_err
    ds["alpha"], ds["alpha_err"] = ("branch", alpha), ("branch", alpha_err)
    ds["glass_phi_j"], ds["glass_phi_j_err"] = ("branch", phi_j), ("branch", phi_j_err)
    ds.attrs.update(liquid_fit_range=list(liquid_range), glass_fit_range=list(glass_range))


def liquid_excess_at(eos: xr.Dataset, phi: float, branch: str | None = None) -> tuple[float, float]:
    """Delta f_L and its error at ``phi`` by the EOS integral of ``branch`` (default: the
    slowest compression), i.e. the trapezoid integral continued to ``phi`` from the nearest bin
    below it with the straight line of (Z - 1)/phi between the bins.

    Parameters
    ----------
    eos : xarray.Dataset
        The EOS summary (:func:`eos_dataset`).
    phi : float
        Volume fraction.
    branch : str, optional
        The branch.

    Returns
    -------
    excess : float
        Delta f_L (NaN outside the branch's bins).
    error : float
        Its error.
    """
    if branch is None:
        branch = eos.attrs.get("cubic_branch")
    row = eos.sel(branch=branch)
    p, z, f, fe = (row[k].values for k in ("phi_mean", "Z", "excess", "excess_err"))
    ok = np.isfinite(f)
    p, z, f, fe = p[ok], z[ok], f[ok], fe[ok]
    if p.size < 2 or not p[0] <= phi <= p[-1]:
        return math.nan, math.nan
    k = int(np.clip(np.searchsorted(p, phi) - 1, 0, p.size - 2))
    y = (z - 1.0) / p
    y_at = np.interp(phi, p, y)
    return float(f[k] + 0.5 * (phi - p[k]) * (y[k] + y_at)), float(max(fe[k], fe[min(k + 1, p.size - 1)]))


def entropy_dataset(eos: xr.Dataset, bcmd: list[xr.Dataset], *, x_large: float,
                    attrs: dict | None = None) -> xr.Dataset:
    """s_c - s_mix = Delta f_g - Delta f_L per SOC glass (Donev 2006, Eq. 13.5, Fig. 13.12).

    Parameters
    ----------
    eos : xarray.Dataset
        The system's EOS summary (:func:`eos_dataset`); Delta f_L from its slowest compression.
    bcmd : list of xarray.Dataset
        BCMD results of the glass snapshots (:func:`hardpack.freeenergy.run_bcmd`), each with the
        attributes ``phi0``, ``growth_rate`` and ``seed`` of its snapshot, and optionally its
        ``coordination_defects`` (:func:`hardpack.structure.coordination_defects`; NaN if absent).
    x_large : float
        Number fraction of the large disks (0 for a monodisperse system): s_mix.

    Returns
    -------
    xarray.Dataset
        Over ``sample`` (indexed by phi0, growth_rate, seed): ``glass_excess``, ``liquid_excess``,
        ``liquid_excess_err``, ``sc_minus_smix``, ``sc_minus_smix_err``, ``sc``, ``dmu_min``,
        ``n_events``, ``seconds``, ``coordination_defects``; attributes ``s_mix``.
    """
    if not bcmd:
        raise InvalidInputError("no BCMD results given")
    s_mix = thermo.mixing_entropy(x_large)
    rows = []
    for ds in bcmd:
        a = ds.attrs
        for key in ("phi0", "growth_rate", "seed"):
            if key not in a:
                raise InvalidInputError(f"BCMD result without the snapshot attribute {key!r}")
        f_l, f_l_err = liquid_excess_at(eos, float(a["phi"]))
        s, s_err = thermo.configurational_entropy_excess(a["excess"], f_l, 0.0, f_l_err)
        rows.append((float(a["phi0"]), float(a["growth_rate"]), int(a["seed"]), float(a["phi"]),
                     float(a["excess"]), f_l, f_l_err, float(s), float(s_err), float(a["dmu_min"]),
                     int(a["n_events"]), float(a["seconds"]), int(a["n_particles"]),
                     float(a.get("coordination_defects", math.nan))))
    rows.sort()
    arr = list(zip(*rows))
    names = ("phi0", "growth_rate", "seed", "phi", "glass_excess", "liquid_excess", "liquid_excess_err",
             "sc_minus_smix", "sc_minus_smix_err", "dmu_min", "n_events", "seconds", "n_particles",
             "coordination_defects")
    data = {n: ("sample", np.asarray(v)) for n, v in zip(names, arr) if n not in ("phi0", "growth_rate", "seed")}
    data["sc"] = ("sample", np.asarray(arr[7]) + s_mix)
    coords = {n: ("sample", np.asarray(v)) for n, v in zip(names[:3], arr[:3])}
    out = xr.Dataset(data, coords=coords)
    out.attrs.update({"hardpack_kind": "glass_entropy", "s_mix": s_mix, "x_large": x_large, **(attrs or {})})
    return out


def joint_branch(eos: xr.Dataset, low: str, high: str, phi_join: float):
    """(phi, Z, Z_err) of one smooth EOS: branch ``low`` below ``phi_join`` and ``high`` from it
    up (monodisperse disks: the liquid compression and the crystal decompression, treated as one
    phase, Donev 2006, sec. 13.2), empty bins dropped.

    Parameters
    ----------
    eos : xarray.Dataset
        The EOS summary (:func:`eos_dataset`).
    low, high : str
        The branches below and above ``phi_join``.
    phi_join : float
        Volume fraction where they join.

    Returns
    -------
    phi, z, z_err : numpy.ndarray of float
        The joined EOS, sorted by phi.
    """
    lo, hi = eos.sel(branch=low), eos.sel(branch=high)
    take_lo = (lo["phi_mean"].values < phi_join) & np.isfinite(lo["Z"].values)
    take_hi = (hi["phi_mean"].values >= phi_join) & np.isfinite(hi["Z"].values)
    parts = [(lo, take_lo), (hi, take_hi)]
    phi = np.concatenate([r["phi_mean"].values[t] for r, t in parts])
    z = np.concatenate([r["Z"].values[t] for r, t in parts])
    z_err = np.concatenate([r["Z_err"].values[t] for r, t in parts])
    order = np.argsort(phi)
    return phi[order], z[order], z_err[order]


def freezing_dataset(mono: xr.Dataset, mixture: xr.Dataset, plus: xr.Dataset | None, minus: xr.Dataset | None,
                     *, kappa: float, x_large: float, dx: float, phi_join: float,
                     replicas: int = FREEZING_REPLICAS) -> xr.Dataset:
    """Freezing of the mixture against the pure large-disk crystal (Eq. 13.2): phi_F and the
    precipitate's density, and the fully phase-separated crystal. The monodisperse EOS joins the
    slowest compression below ``phi_join`` and the decompression of the crystal above; the
    mixture's EOS is its slowest compression; mu~_B from the mixtures at x_A +- dx (``plus``:
    x_A + dx, i.e. x_large - dx), or 0 without them (recorded in ``mu_tilde``). Data that do not
    allow a solution (too few points, no sign change) give NaN with the reason in ``status``.

    Standard errors by a parametric bootstrap: ``replicas`` times, every binned Z of every
    input is drawn from a normal distribution with its standard error Z_err (bins independent,
    the model under which :func:`hardpack.glass.thermo.excess_free_energy` propagates them), the
    excess free energies are integrated again and Eq. 13.2 solved again; the error of each
    result is the standard deviation over the replicas that solve (their number is the attribute
    ``replicas_solved``). The draws use a fixed seed, so the same inputs give the same errors.

    Parameters
    ----------
    mono : xarray.Dataset
        EOS summary of the monodisperse system.
    mixture : xarray.Dataset
        EOS summary of the mixture.
    plus, minus : xarray.Dataset or None
        EOS summaries at x_A + dx and x_A - dx.
    kappa : float
        Diameter ratio.
    x_large : float
        Number fraction of the large disks.
    dx : float
        Composition step of ``plus`` and ``minus``.
    phi_join : float
        Where the monodisperse compression and decompression join.
    replicas : int, default FREEZING_REPLICAS
        Bootstrap replicas of the standard errors (0: no errors, NaN).

    Returns
    -------
    xarray.Dataset
        Scalars phi_freeze, phi_precipitate, pressure, mu and their standard errors (``*_err``);
        attributes status, mu_tilde, replicas and replicas_solved. The fully phase-separated
        crystal (:func:`hardpack.glass.freezing.separated_crystal`, Fig. 13.4) from the same
        monodisperse EOS: scalars phi_a_melts, phi_b_melts (with ``*_err``), the phase densities
        phi_a, phi_b and the reduced pressure z_separated over ``phi``; attributes
        separated_status and separated_replicas_solved.

    Raises
    ------
    InvalidInputError
        If ``replicas`` is not an integer >= 0.
    """
    if isinstance(replicas, bool) or not isinstance(replicas, (int, np.integer)) or replicas < 0:
        raise InvalidInputError(f"replicas must be an integer >= 0 (0: no error estimate), got {replicas!r}")
    attrs = {"hardpack_kind": "glass_freezing", "kappa": kappa, "x_large": x_large, "phi_join": phi_join,
             "n_particles": int(mixture.attrs.get("N", 0)), "phi_transition": SEPARATED_TRANSITION}
    names = ("phi_freeze", "phi_precipitate", "pressure", "mu")
    separated_names = ("phi_a_melts", "phi_b_melts")
    values, separated = dict.fromkeys(names, math.nan), dict.fromkeys(separated_names, math.nan)
    try:
        values, how = _solve_freezing(mono, mixture, plus, minus, kappa, x_large, dx, phi_join)
        attrs.update(status="solved", mu_tilde=how)
    except InvalidInputError as exc:
        attrs.update(status=f"not solved: {exc}", mu_tilde="-")
    try:
        separated, curve, span = _solve_separated(mono, kappa, x_large, phi_join)
        attrs.update(separated_status="solved", separated_span=span)
    except InvalidInputError as exc:
        curve = None
        attrs.update(separated_status=f"not solved: {exc}")
    draws, separated_draws = [], []
    rng = np.random.default_rng(FREEZING_SEED)
    for _ in range(int(replicas)):
        inputs = [None if eos is None else _perturbed_eos(eos, rng) for eos in (mono, mixture, plus, minus)]
        if attrs["status"] == "solved":
            try:
                draws.append(_solve_freezing(*inputs, kappa, x_large, dx, phi_join)[0])
            except InvalidInputError:
                pass
        if curve is not None:
            try:
                separated_draws.append(_solve_separated(inputs[0], kappa, x_large, phi_join, curves=False)[0])
            except InvalidInputError:
                pass

    def spread(samples, keys):
        if len(samples) < 2:
            return dict.fromkeys(keys, math.nan)
        return {k: float(np.std([r[k] for r in samples], ddof=1)) for k in keys}

    errors = spread(draws, names) | spread(separated_draws, separated_names)
    attrs.update(replicas=int(replicas), replicas_solved=len(draws), separated_replicas_solved=len(separated_draws))
    scalars = values | separated
    data = {k: ((), scalars[k]) for k in scalars} | {f"{k}_err": ((), errors[k]) for k in scalars}
    coords = {}
    if curve is not None:
        coords["phi"] = ("phi", curve.phi)
        data.update(phi_a=("phi", curve.phi_a), phi_b=("phi", curve.phi_b), z_separated=("phi", curve.z))
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _solve_separated(mono, kappa, x_large, phi_join, curves: bool = True):
    """The fully phase-separated crystal of the mixture from the monodisperse EOS (Donev 2006,
    sec. 13.2.2.1): the overall densities at which each phase reaches the transition, the
    phase densities over SEPARATED_PHI, and the melting densities across the printed transition
    region (text)."""
    from hardpack.glass import freezing as fz

    pure, mix = _mono_phase(mono, phi_join), fz.Mixture(kappa, x_large)
    a_melts, b_melts = fz.separated_melting(pure, mix, SEPARATED_TRANSITION)
    if not curves:
        return {"phi_a_melts": a_melts, "phi_b_melts": b_melts}, None, ""
    curve = fz.separated_crystal(pure, mix, SEPARATED_PHI)
    ends = [fz.separated_melting(pure, mix, t) for t in SEPARATED_TRANSITION_SPAN]
    span = (f"for a transition at {SEPARATED_TRANSITION_SPAN[0]}-{SEPARATED_TRANSITION_SPAN[1]}: A melts at "
            f"{ends[0][0]:.4f}-{ends[1][0]:.4f}, B at {ends[0][1]:.4f}-{ends[1][1]:.4f}")
    return {"phi_a_melts": a_melts, "phi_b_melts": b_melts}, curve, span


def _perturbed_eos(eos: xr.Dataset, rng: np.random.Generator) -> xr.Dataset:
    """A copy of an EOS summary with every finite Z drawn from N(Z, Z_err) and the excess free
    energies of its compression branches integrated again over the same bins (as
    :func:`eos_dataset` does)."""
    out = eos.copy(deep=True)
    z_all, err_all = out["Z"].values, out["Z_err"].values
    excess_all, phi_all = out["excess"].values, out["phi_mean"].values
    for b in range(z_all.shape[0]):
        ok = np.isfinite(z_all[b])
        z_all[b, ok] += rng.normal(size=int(ok.sum())) * np.nan_to_num(err_all[b, ok])
        span = np.flatnonzero(ok & np.isfinite(excess_all[b]))
        if span.size:
            excess_all[b, span] = thermo.excess_free_energy(phi_all[b, span], z_all[b, span],
                                                            slope0=float(eos.attrs["slope0"]))[0]
    return out


def _mono_phase(mono, phi_join):
    """The monodisperse disks as one phase: the slowest compression below ``phi_join``, the
    crystal's decompression above, with the EOS integral from the ideal gas."""
    from hardpack.glass import freezing as fz

    p, z, ze = joint_branch(mono, mono.attrs["cubic_branch"], "decompression", phi_join)
    f, _ = thermo.excess_free_energy(p, z, ze, slope0=thermo.second_virial_slope(2))
    return fz.tabulated_phase(p, z, f)


def _solve_freezing(mono, mixture, plus, minus, kappa, x_large, dx, phi_join):
    from hardpack.glass import freezing as fz

    pure = _mono_phase(mono, phi_join)

    def branch_phase(eos):
        row = eos.sel(branch=eos.attrs["cubic_branch"])
        ok = np.isfinite(row["excess"].values)
        return fz.tabulated_phase(row["phi_mean"].values[ok], row["Z"].values[ok], row["excess"].values[ok])

    mix_phase = branch_phase(mixture)
    mu_tilde, how = 0.0, "0 (no neighbouring compositions)"
    if plus is not None and minus is not None:
        fp, fm = branch_phase(plus), branch_phase(minus)
        lo, hi = max(fp.phi_lo, fm.phi_lo), min(fp.phi_hi, fm.phi_hi)
        mix_phase = fz.Phase(mix_phase.z, mix_phase.excess, max(mix_phase.phi_lo, lo),
                             min(mix_phase.phi_hi, hi))
        mu_tilde, how = fz.composition_derivative(fp.excess, fm.excess, dx), f"central difference, dx = {dx}"
    res = fz.freezing_point(pure, mix_phase, fz.Mixture(kappa, x_large), mu_tilde)
    return {"phi_freeze": res.phi_freeze, "phi_precipitate": res.phi_precipitate,
            "pressure": res.pressure, "mu": res.mu}, how


def relaxed_dataset(fast: list[xr.Dataset], jammed: list[xr.Dataset], *, relax_collisions: float) -> xr.Dataset:
    """Jamming densities of fast glasses before and after relaxation (Donev 2006, sec. 13.3.1 and
    Fig. 13.8: "fast compressions produce packings that are not truly jammed and subsequent
    relaxation of these systems increases the density to around phi_J ~ 0.847").

    Each run is a fast LS compression of the liquid to a high pressure (``fast``), then MD at fixed
    phi for ``relax_collisions`` collisions per particle, then a slow compression to a high pressure
    (``jammed``). phi_J of each is the packing's phi~_J = phi / (1 - d/Z) (Eq. 13.4's estimate).

    Parameters
    ----------
    fast, jammed : list of xarray.Dataset
        The packings after the fast compression and after the recompression, run by run.
    relax_collisions : float
        Collisions per particle of the relaxation at fixed phi (recorded).

    Returns
    -------
    xarray.Dataset
        Over ``run``: ``rate`` (the fast growth rate), ``seed``, ``phi_J_fast``, ``Z_fast``,
        ``phi_J``, ``Z``; kind ``glass_relaxed``; attributes N, recompress_rate, relax_collisions.

    Raises
    ------
    InvalidInputError
        If the lists differ in length, are empty, or pair packings of different N or seed.
    """
    if not fast or len(fast) != len(jammed):
        raise InvalidInputError(f"need one recompressed packing per fast packing; got {len(fast)} and {len(jammed)}")
    cols = {k: [] for k in ("rate", "seed", "phi_J_fast", "Z_fast", "phi_J", "Z")}
    n = {int(p.attrs["N"]) for p in fast + jammed}
    slow = {float(p.attrs["growth_rate"]) for p in jammed}
    if len(n) != 1 or len(slow) != 1:
        raise InvalidInputError(f"all packings must have one N and the recompressions one rate; got N {sorted(n)}, "
                                f"rates {sorted(slow)}")
    for a, b in zip(fast, jammed):
        if int(a.attrs["seed"]) != int(b.attrs["seed"]):
            raise InvalidInputError(f"fast packing of seed {a.attrs['seed']} paired with a recompression of seed "
                                    f"{b.attrs['seed']}: give them in the same order")
        for key, value in (("rate", float(a.attrs["growth_rate"])), ("seed", int(a.attrs["seed"])),
                           ("phi_J_fast", float(a.attrs["phi_J_est"])), ("Z_fast", float(a.attrs["Z"])),
                           ("phi_J", float(b.attrs["phi_J_est"])), ("Z", float(b.attrs["Z"]))):
            cols[key].append(value)
    ds = xr.Dataset({k: ("run", np.array(v)) for k, v in cols.items() if k not in ("rate", "seed")},
                    coords={"rate": ("run", np.array(cols["rate"])), "seed": ("run", np.array(cols["seed"]))})
    ds.attrs.update(hardpack_kind="glass_relaxed", N=n.pop(), recompress_rate=slow.pop(),
                    relax_collisions=float(relax_collisions))
    return ds
