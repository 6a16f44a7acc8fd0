"""Bounding-cell molecular dynamics (BCMD): free energy of a hard-sphere solid from the kinetic
energy gained while its single-occupancy cells shrink.

Donev 2006, dissertation sec. 6.3 (the journal version is Donev et al. 2007, Sec. 3). Conventions
(secs. 6.3.1 and 6.3.4; where the text is silent, our choices are stated below):

- Each moving sphere i (radius R_i, mass 1) lives in a hard spherical cell of radius mu R_i with
  mu = 1 + Delta mu, centred on its initial position R_i^0, so its centre obeys
  |r_i - R_i^0| <= Delta mu(t) R_i. **Delta mu is dimensionless, in units of the particle's own
  radius** (for unit-diameter spheres the centre moves in a ball of radius Delta mu / 2).
- Two spheres can collide only if their cells overlap: a static neighbour list of the pairs with
  |R_i^0 - R_j^0| <= (1 + Delta mu_max)(R_i + R_j) is built once, each row sorted by that
  ratio, and every segment uses only the prefix of pairs whose cells can still overlap (FCC at
  melting: 42 neighbours at Delta mu = 1, 12 below 0.566).
- The cells shrink at d(Delta mu)/dt = -gamma(Delta mu), gamma = gamma_0 (Delta mu /
  Delta mu_max)^theta (sec. 6.3.4), updated each time Delta mu has fallen by the fraction
  ``segment_fraction``; wall collisions use v_n' = 2 w - v_n, w = -gamma R_i (sec. 6.3.3).
- Translations: ``frozen="particle"`` freezes particle 0 (infinite mass), N_eff = N - 1;
  ``frozen="cm"`` measures K in the centre-of-mass frame, N_f = d (N - 1). Per sec. 6.3.4.1
  the two free energies differ by d ln N / N; in both modes the reference f_c below is the mean
  over the moving particles, so the CM-mode number is f_c - (d/2) ln(K_cm/K_0) as in Donev's
  frozen-CM row of Table 6.1 (its exact finite-N normalisation, sec. 6.3.4.1, is not reproduced here).
- Estimator (Eqs. 6.12-6.13, secs. 6.3.2-6.3.3): ln(V / V_min) = (N_f / 2) ln(K / K_0), chained over
  velocity re-draws; per particle Delta f = ln(V/V_min) / N_eff = (d/2) ln(K/K_0).
- Result: f = f_c(Delta mu_min) - Delta f with the disjoint-cell reference
  f_c = -<ln(|B_d| (Delta mu_min R_i)^d)>_moving (Eq. 6.10; = -d ln Delta mu - ln V_p for
  unit-diameter spheres); lengths are in units of the mean diameter 2<R>. The excess over the
  ideal gas uses f_ideal = -ln(V/N) - 1 (Eq. 6.15). At Delta mu_min = delta of a jammed packing
  shrunk by (1 - delta), Delta f = f_J - f_c^J (Eq. 6.18).
- Diagnostic: cell pressure p_c = <F_wall> mu R / (d kT) per segment (derived here:
  V_c/S_c = mu R / d for a spherical cell; the integrand of Eq. 6.9), which tends to mu / Delta mu
  for disjoint cells (the asymptote of Fig. 6.4).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.freeenergy import _kernel as kern
from hardpack.geometry.balls import unit_ball_volume
from hardpack.geometry.neighbours import pairs_within
from hardpack.geometry.packing import Packing

log = logging.getLogger("hardpack.freeenergy")

#: seconds of CPU time between progress lines of :func:`run_bcmd`
PROGRESS_INTERVAL = 60.0

FROZEN_MODES = ("particle", "cm")


@dataclass(frozen=True)
class Neighbours:
    """Static CSR neighbour list: for particle i, entries start[i]:start[i+1] hold the partner j,
    the cell-centre vector D_ij = R_j^0 (image) - R_i^0, the contact distance R_i + R_j and
    ratio = |D_ij| / (R_i + R_j), sorted by ratio within each row (so the pairs whose cells still
    overlap at Delta mu, ratio <= 1 + Delta mu, are a prefix of the row: :meth:`active_end`).

    Attributes
    ----------
    start : numpy.ndarray of int64, shape (N + 1,)
        Row starts.
    j : numpy.ndarray of int64, shape (P,)
        Partner of every entry.
    disp : numpy.ndarray of float, shape (P, d)
        D_ij.
    sig : numpy.ndarray of float, shape (P,)
        R_i + R_j.
    ratio : numpy.ndarray of float, shape (P,)
        |D_ij| / (R_i + R_j).
    """

    start: np.ndarray
    j: np.ndarray
    disp: np.ndarray
    sig: np.ndarray
    ratio: np.ndarray

    def active_end(self, dmu: float) -> np.ndarray:
        """End of each row's prefix of pairs whose cells of radius (1 + dmu) R can overlap.

        Parameters
        ----------
        dmu : float
            Relative cell size Delta mu; entries with ratio <= 1 + dmu (up to a relative 1e-12) count.

        Returns
        -------
        numpy.ndarray of int64, shape (N,)
            For particle i, the active entries are start[i]:end[i] (the rows are sorted by ratio).
        """
        owner = np.repeat(np.arange(self.start.size - 1), np.diff(self.start))
        keep = self.ratio <= (1.0 + dmu) * (1.0 + 1e-12)
        counts = np.bincount(owner[keep], minlength=self.start.size - 1)
        return self.start[:-1] + counts


def cell_neighbours(packing: Packing, dmu_max: float) -> Neighbours:
    """Pairs whose cells of radius (1 + dmu_max) R overlap, both directions, self-images
    dropped (a particle and its own image move together and never collide).

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing (the cell centres R^0 and radii R).
    dmu_max : float
        Largest relative cell size Delta mu.

    Returns
    -------
    Neighbours
        The neighbour list.

    Raises
    ------
    InvalidInputError
        Unless the packing holds spheres in a periodic cell.
    """
    packing.require_periodic_spheres("BCMD")
    pl = pairs_within(packing, rel_gap=dmu_max)
    keep = pl.i != pl.j
    i, j, sep = pl.i[keep], pl.j[keep], pl.separation[keep]
    ii = np.concatenate([i, j])
    jj = np.concatenate([j, i])
    disp = np.concatenate([sep, -sep])
    sig = packing.radii[ii] + packing.radii[jj]
    ratio = np.linalg.norm(disp, axis=1) / sig if ii.size else np.zeros(0)
    order = np.lexsort((ratio, ii))
    ii, jj, disp, sig, ratio = ii[order], jj[order], disp[order], sig[order], ratio[order]
    start = np.searchsorted(ii, np.arange(packing.n_particles + 1)).astype(np.int64)
    return Neighbours(
        start, jj.astype(np.int64), np.ascontiguousarray(disp, float), sig, ratio
    )


def disjoint_dmu(nb: Neighbours) -> float:
    """Largest Delta mu at which all cells are pairwise disjoint: min |D_ij| / (R_i + R_j) - 1.

    Parameters
    ----------
    nb : Neighbours
        The neighbour list.

    Returns
    -------
    float
        Delta mu_d (inf without pairs).
    """
    if nb.j.size == 0:
        return np.inf
    return float(np.min(nb.ratio) - 1.0)


@dataclass(frozen=True)
class BCMDResult:
    """Outcome of :func:`run_bcmd`; :meth:`to_dataset` gives the per-segment series and all numbers.

    Attributes
    ----------
    delta_f : float
        (d/2) ln(K/K_0) chained = f_c(Delta mu_min) - f.
    f_c : float
        Disjoint-cell reference at Delta mu_min (lengths in mean diameters); NaN for a partial run.
    f : float
        Free energy per moving particle; NaN for a partial run.
    excess : float
        f - f_ideal with f_ideal = -ln(V/N) - 1 (Eq. 6.15).
    """

    delta_f: float  # (d/2) ln(K/K0) chained = f_c(dmu_min) - f
    f_c: float  # disjoint-cell reference at dmu_min (units: mean diameter)
    f: float  # free energy per moving particle
    excess: float  # f - f_ideal
    _dataset: xr.Dataset = field(repr=False)

    def to_dataset(self) -> xr.Dataset:
        """The per-segment series (dimension ``segment``) with every parameter and number of the
        run in its attributes (a copy: changing it leaves the result as it is)."""
        return self._dataset.copy()


def _check(name, value, lo=0.0, hi=np.inf, lo_open=True):
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    ok = np.isfinite(x) and (x > lo if lo_open else x >= lo) and x <= hi
    if not ok:
        raise InvalidInputError(
            f"{name} = {value!r} must be finite and in {'(' if lo_open else '['}{lo}, {hi}]"
        )
    return x


def _check_schedule(dmu_max, gamma0, theta, equilibration, segment_fraction) -> tuple[float, ...]:
    """The shrink schedule's parameters (:func:`shrink_schedule`) and the equilibration time as
    floats, refused when out of range."""
    dmu_max = _check("dmu_max", dmu_max)
    gamma0 = _check("gamma0", gamma0)
    theta = _check("theta", theta, lo=0.0, lo_open=False)
    equilibration = _check("equilibration", equilibration, lo=0.0, lo_open=False)
    segment_fraction = _check("segment_fraction", segment_fraction, hi=0.5)
    return dmu_max, gamma0, theta, equilibration, segment_fraction


def shrink_schedule(dmu_max: float, dmu_min: float, gamma0: float, theta: float, segment_fraction: float):
    """The segments of the BCMD shrink schedule (module docstring): the cell size falls from
    ``dmu_max`` to ``dmu_min`` by the factor 1 - ``segment_fraction`` a segment (the last one
    ends at ``dmu_min``) at the rate gamma = gamma0 (dmu / dmu_max)^theta of its start.

    Parameters
    ----------
    dmu_max, dmu_min : float
        First and last cell size Delta mu.
    gamma0 : float
        Shrink rate at ``dmu_max``.
    theta : float
        Schedule exponent.
    segment_fraction : float
        Relative shrink of one segment, in (0, 1).

    Yields
    ------
    dmu, dmu_next, gamma, dt : float
        Cell size at the start and end of the segment, its rate and its duration
        (dmu - dmu_next) / gamma.
    """
    dmu = dmu_max
    while dmu > dmu_min * (1 + 1e-12):
        gamma = gamma0 * (dmu / dmu_max) ** theta
        dmu_next = max(dmu * (1.0 - segment_fraction), dmu_min)
        yield dmu, dmu_next, gamma, (dmu - dmu_next) / gamma
        dmu = dmu_next


def run_bcmd(
    packing: Packing,
    *,
    dmu_max: float,
    dmu_min: float | None = None,
    gamma0: float = 1e-3,
    theta: float = 1.0,
    frozen: str = "particle",
    seed: int = 0,
    equilibration: float = 50.0,
    segment_fraction: float = 0.01,
    reset_ratio: float | None = None,
    max_events: int = 10**10,
    partial: bool = False,
) -> BCMDResult:
    """Run BCMD on ``packing`` (cell centres = its positions, radii as given) from Delta mu_max
    down to Delta mu_min (default: the disjoint-cell point, which must be > 0).

    Conventions and estimator: see the module docstring (Donev 2006, sec. 6.3).

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing with at least 2 particles; its positions are the cell centres.
    dmu_max : float
        Initial cell size Delta mu_max (> 0), in units of each particle's radius.
    dmu_min : float, optional
        Final cell size Delta mu_min, 0 < dmu_min < dmu_max; default the disjoint-cell point
        min |R_i - R_j| / (R_i + R_j) - 1.
    gamma0 : float, default 1e-3
        Shrink rate gamma_0 > 0 at Delta mu_max.
    theta : float, default 1.0
        Exponent of gamma = gamma_0 (Delta mu / Delta mu_max)^theta, >= 0.
    frozen : {"particle", "cm"}, default "particle"
        Removal of the translations: freeze particle 0, or measure K in the centre-of-mass frame.
    seed : int, default 0
        Seed of the initial and re-drawn velocities.
    equilibration : float, default 50.0
        Run time at fixed Delta mu_max before shrinking, in units of Delta mu_max <R> / v_th
        (v_th = 1); >= 0.
    segment_fraction : float, default 0.01
        Relative fall of Delta mu per segment (the rate gamma is updated and one row recorded
        per segment); in (0, 0.5].
    reset_ratio : float, optional
        If set (> 1), velocities are re-drawn (kT back to its initial value) whenever K grew by
        this factor since the last draw (thermostat of Donev 2006, sec. 6.3.5.1); ln K is
        chained across draws.
    max_events : int, default 10**10
        Bound on the collisions of one segment.
    partial : bool, default False
        Allow stopping above the disjoint-cell point (the Delta f(Delta mu) curve only; f_c, f
        and the excess are then NaN).

    Returns
    -------
    BCMDResult
        ``delta_f`` = (d/2) ln(K/K_0) chained, ``f_c`` the disjoint-cell reference at
        Delta mu_min, ``f`` = f_c - delta_f per moving particle, ``excess`` = f - f_ideal, and
        ``dataset``: per-segment variables ``dmu``, ``mu``, ``dmu_mid``, ``time``, ``gamma``,
        ``ln_k``, ``delta_f``, ``p_c`` (reduced cell-wall pressure), ``events``, with the
        parameters, results and event counts in its attrs (``hardpack_kind`` = "bcmd").

    Raises
    ------
    InvalidInputError
        If ``packing`` is not a periodic sphere Packing with >= 2 particles, ``frozen`` is
        unknown, a numeric parameter is outside its range, the cells are never disjoint (some
        centres at contact), dmu_min >= dmu_max, or dmu_min is above the disjoint-cell point
        without ``partial``.
    RuntimeError
        If a segment exceeds ``max_events``, a particle escapes its cell or two spheres overlap
        at the end (failures of the event-driven dynamics, not of the input).
    """
    clock = time.perf_counter()
    if not isinstance(packing, Packing):
        raise InvalidInputError("packing must be a hardpack Packing")
    packing.require_periodic_spheres("BCMD")
    d, n = packing.dim, packing.n_particles
    if frozen not in FROZEN_MODES:
        raise InvalidInputError(f"frozen must be one of {FROZEN_MODES}, got {frozen!r}")
    if n < 2:
        raise InvalidInputError(
            "BCMD needs at least 2 particles (one is frozen or the CM is fixed)"
        )
    dmu_max, gamma0, theta, equilibration, segment_fraction = _check_schedule(
        dmu_max, gamma0, theta, equilibration, segment_fraction)
    if reset_ratio is not None:
        reset_ratio = _check("reset_ratio", reset_ratio, lo=1.0)
    nb = cell_neighbours(packing, dmu_max)
    disjoint = disjoint_dmu(nb)
    if not disjoint > 0:
        raise InvalidInputError(
            "the cells are never disjoint (some centres are at contact): shrink the particles "
            "slightly (e.g. --delta 1e-6) so that min |R_i - R_j| > R_i + R_j"
        )
    if dmu_min is None:
        dmu_min = disjoint
    dmu_min = _check("dmu_min", dmu_min)
    if dmu_min >= dmu_max:
        raise InvalidInputError(
            f"dmu_min = {dmu_min:.6g} must be below dmu_max = {dmu_max:.6g} (the cells are "
            f"disjoint below {disjoint:.6g}; pass a smaller dmu_min or a larger dmu_max)"
        )
    if dmu_min > disjoint * (1 + 1e-12) and not partial:
        raise InvalidInputError(
            f"dmu_min = {dmu_min:.6g} is above the disjoint-cell point {disjoint:.6g}: the final "
            "state would not be the exactly known reference (leave dmu_min unset, or pass "
            "partial=True for the Delta f(Delta mu) curve only)"
        )
    exact_end = dmu_min <= disjoint * (1 + 1e-12)

    rng = np.random.default_rng(seed)
    radii = packing.radii.astype(float)
    invm = np.ones(n)
    if frozen == "particle":
        invm[0] = 0.0
    moving = invm > 0
    n_moving = int(moving.sum())
    n_f = d * (n - 1)
    n_eff = n - 1

    def kinetic(v):
        k = 0.5 * float(np.sum(v[moving] ** 2))
        if frozen == "cm":
            p = v.sum(axis=0)
            k -= 0.5 * float(p @ p) / n
        return k

    def draw(kt):
        v = rng.normal(size=(n, d))
        v[~moving] = 0.0
        if frozen == "cm":
            v -= v.mean(axis=0)
        return v * np.sqrt(0.5 * n_f * kt / kinetic(v))

    state = np.zeros((n, 2 * d + 1))  # rows (dr, v, time), see hardpack.freeenergy._kernel
    dr, v = state[:, :d], state[:, d : 2 * d]
    v[:] = draw(1.0)
    facc = np.zeros(kern.N_FLOAT)
    iacc = np.zeros(kern.N_INT, np.int64)

    def segment(dmu, gamma, duration):
        return kern.run_segment(
            state, radii, invm, nb.start, nb.active_end(dmu), nb.j, nb.disp, nb.sig,
            dmu, gamma, duration, facc, iacc, max_events,
        )

    t = 0.0
    t_eq = equilibration * dmu_max * radii.mean()
    if t_eq > 0:
        segment(dmu_max, 0.0, t_eq)
        t = t_eq
    k0 = kinetic(v)
    k_draw = k0
    ln_k = 0.0  # chained ln(K/K0)
    n_redraws = 0
    rows = []
    steps = math.ceil(math.log(dmu_min / dmu_max) / math.log1p(-segment_fraction))
    reported = time.process_time()
    for dmu, dmu_next, gamma, dt in shrink_schedule(dmu_max, dmu_min, gamma0, theta, segment_fraction):
        if time.process_time() - reported >= PROGRESS_INTERVAL:
            reported = time.process_time()
            log.info("BCMD: cell step %d of about %d, dmu = %.4g (down to %.4g), %.3g events, kT = %.3g",
                     len(rows), steps, dmu, dmu_min, float(iacc[kern.C_EVENTS]), kinetic(v) / (0.5 * n_f))
        facc[:] = 0.0
        ev_before = iacc[kern.C_EVENTS]
        k_start = kinetic(v)
        done = segment(dmu, gamma, dt)
        if done >= max_events:
            raise RuntimeError(
                f"segment at dmu = {dmu:.4g} exceeded max_events = {max_events}"
            )
        t += dt
        excursion = np.max(
            np.linalg.norm(dr[moving], axis=1) / (radii[moving] * dmu_next)
        )
        if excursion > 1.0 + 1e-8:
            raise RuntimeError(
                f"a particle escaped its cell (|dr|/rho = {excursion:.12g}) at dmu = {dmu_next:.4g}"
            )
        k_end = kinetic(v)
        kt_mid = (k_start + k_end) / n_f
        mu_mid = 1.0 + 0.5 * (dmu + dmu_next)
        p_c = facc[kern.F_WALL_IMPULSE_R] * mu_mid / (d * n_moving * dt * kt_mid)
        ln_k += np.log(k_end / k_draw)
        k_draw = k_end
        if reset_ratio is not None and k_end > reset_ratio * k0:
            v[:] = draw(k0 / (0.5 * n_f))
            k_draw = k0
            n_redraws += 1
        rows.append(
            (
                dmu_next,
                0.5 * (dmu + dmu_next),
                t,
                gamma,
                ln_k,
                p_c,
                iacc[kern.C_EVENTS] - ev_before,
            )
        )
    min_gap = _min_gap(nb, dr)
    if min_gap < -1e-9:
        raise RuntimeError(
            f"two spheres overlap by {-min_gap:.3g} at the end of the run"
        )

    arr = np.array(rows, dtype=float)
    unit = 2.0 * radii.mean()
    log_cells = np.log(unit_ball_volume(d)) + d * np.log(dmu_min * radii[moving] / unit)
    f_c = -float(np.mean(log_cells)) if exact_end else np.nan
    delta_f = 0.5 * n_f * ln_k / n_eff
    f = f_c - delta_f
    f_ideal = -np.log(packing.volume / unit**d / n) - 1.0
    attrs = {
        "hardpack_kind": "bcmd",
        "n_particles": n,
        "dim": d,
        "phi": packing.phi,
        "frozen": frozen,
        "n_f": n_f,
        "n_eff": n_eff,
        "dmu_max": dmu_max,
        "dmu_min": dmu_min,
        "dmu_disjoint": disjoint,
        "gamma0": gamma0,
        "theta": theta,
        "seed": seed,
        "equilibration": equilibration,
        "segment_fraction": segment_fraction,
        "reset_ratio": -1.0 if reset_ratio is None else reset_ratio,
        "length_unit": unit,
        "delta_f": delta_f,
        "f_c": f_c,
        "f": f,
        "f_ideal": f_ideal,
        "excess": f - f_ideal,
        "k0": k0,
        "n_events": int(iacc[kern.C_EVENTS]),
        "n_wall": int(iacc[kern.C_WALL]),
        "n_pair": int(iacc[kern.C_PAIR]),
        "n_stale": int(iacc[kern.C_STALE]),
        "final_min_gap": min_gap,
        "n_redraws": n_redraws,
        "seconds": time.perf_counter() - clock,
    }
    ds = xr.Dataset(
        {
            "dmu": (
                "segment",
                arr[:, 0],
                {"long_name": "cell size Delta mu at segment end"},
            ),
            "mu": ("segment", 1.0 + arr[:, 0]),
            "dmu_mid": ("segment", arr[:, 1]),
            "time": ("segment", arr[:, 2]),
            "gamma": ("segment", arr[:, 3]),
            "ln_k": ("segment", arr[:, 4], {"long_name": "chained ln(K/K0)"}),
            "delta_f": ("segment", 0.5 * n_f * arr[:, 4] / n_eff),
            "p_c": ("segment", arr[:, 5], {"long_name": "reduced cell-wall pressure"}),
            "events": ("segment", arr[:, 6].astype(np.int64)),
        },
        attrs=attrs,
    )
    return BCMDResult(delta_f, f_c, f, f - f_ideal, ds)


def _min_gap(nb: Neighbours, dr: np.ndarray) -> float:
    i = np.repeat(np.arange(nb.start.size - 1), np.diff(nb.start))
    r = nb.disp + dr[nb.j] - dr[i]
    if r.size == 0:
        return np.inf
    return float(np.min(np.linalg.norm(r, axis=1) - nb.sig))
