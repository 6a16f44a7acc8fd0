"""Structure factor S(k), its k -> 0 extrapolation, and the number variance in spherical windows.

**S(k)** (Donev 2006, sec. 10.3; Ogarko 2014, Eq. 3.58):
S(k) = |sum_j exp(-i k.x_j)|^2 / N for the wavevectors allowed by the periodic cell,
k = 2 pi L^-T n (n integer, L = lattice with vectors as columns), so k.x_j = 2 pi n.s_j with the
fractional coordinates s_j. S(k) = S(-k), so only one of +-n is computed. This is freud's
StaticStructureFactorDirect convention, S(k) = (1/N) sum_ij exp(i k.r_ij), at k != 0. For the
ideal gas E[S(k)] = 1 exactly at every allowed k != 0 and S(k) is exponentially distributed
(variance 1), so a shell average over m vectors has noise 1/sqrt(m). For a perfect lattice S = 0
at allowed k off the Bragg peaks and N |F(k)|^2 / n_b^2 on them (N for a Bravais lattice).

The direct sum is evaluated exactly (no FFT gridding): the density modes
rho(n) = sum_j prod_a exp(-2 pi i n_a s_ja) factorise over the axes, so for each group of
vectors sharing (n_1 .. n_(d-1)) the sum over particles and all n_d is one complex matrix
product (BLAS), with the per-axis phase tables computed once per particle chunk.

**Shell average** over spherical shells of thickness 2 pi / V^(1/d) (2 pi / L for a cubic box,
Donev 2006, sec. 10.3); each shell reports its mean |k|, mean S, the standard error of the mean and
the number of vectors.

**S(0)** (Donev 2006, sec. 10.3, Fig. 10.2): weighted least squares of the shell means for k <= k_fit, linear
S = S0 + s1 k (Donev's fit for jammed packings, K/2pi < 0.4 with K = kD) or even quadratic
S = S0 + s2 k^2 (the liquid form), weights = number of vectors per shell; the error comes from
the residual scatter.

**Number variance** (Donev 2006, sec. 10.4): sigma^2(R) = <N_R^2> - <N_R>^2 of the number of centres
(all periodic images) inside windows of radius R with uniformly random centres; the standard
error ``variance_err`` covers only the window sampling: one configuration's variance also
fluctuates with the configuration (it is a sum of S(k) |window transform|^2 dominated by the
few allowed k below ~pi/R), so average over packings. Averaged over ideal-gas configurations
the count is exactly binomial: sigma^2 = N p (1 - p), p = v_d R^d / V (R below half the cell
width).
"""

from __future__ import annotations

import math

import numba
import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours import build_grid
from hardpack.geometry.neighbours.grid import window_counts

_PARTICLE_CHUNK = 8192  # particles per phase table
_MATRIX_ELEMENTS = 2**21  # rows x particles per GEMM block (operand ~32 MB)


def _check_k_max(k_max):
    if k_max is None or not np.isfinite(k_max) or k_max <= 0:
        raise InvalidInputError(f"k_max must be a positive finite number, got {k_max!r}")
    return float(k_max)


def _times_transpose(n, m):
    """n @ m.T for a tall (M, d) array n and a small (d, d) matrix m, as d axpy passes (BLAS is
    slow for this shape)."""
    out = np.zeros((len(n), m.shape[0]))
    for a in range(m.shape[1]):
        out += n[:, a, None] * m[None, :, a]
    return out


def _heads(lattice, k_max: float, max_vectors: int):
    """Wavevectors grouped by head h = (n_1 .. n_(d-1)): each head carries the range
    t_lo..t_hi of the last component with |k| <= k_max (roots of the quadratic in t), and only
    one of +-n is kept (lexicographically positive half space; the zero head keeps t >= 1)."""
    lattice = np.asarray(lattice, dtype=float)
    k_max = _check_k_max(k_max)
    d = lattice.shape[0]
    recip = 2.0 * np.pi * np.linalg.inv(lattice).T  # columns are the reciprocal vectors
    n_lim = np.floor(k_max * np.linalg.norm(lattice, axis=0) / (2 * np.pi)).astype(np.int64)
    if np.prod(2.0 * n_lim[:-1] + 1) > max_vectors:
        raise InvalidInputError(f"k_max = {k_max} needs too many wavevectors; lower k_max")
    if d > 1:
        heads = np.stack(np.meshgrid(*[np.arange(-m, m + 1) for m in n_lim[:-1]], indexing="ij"),
                         axis=-1).reshape(-1, d - 1)
        first = np.argmax(heads != 0, axis=1)
        heads = heads[heads[np.arange(len(heads)), first] >= 0]  # sign of the first nonzero
    else:
        heads = np.zeros((1, 0), np.int64)
    zero = ~heads.any(axis=1)
    kh = _times_transpose(heads, recip[:, :-1])
    b = recip[:, -1]
    qa, qb = b @ b, kh @ b
    disc = qb**2 - qa * (np.einsum("ij,ij->i", kh, kh) - k_max**2)
    ok = disc >= 0
    root = np.sqrt(np.where(ok, disc, 0.0))
    t_lo = np.ceil((-qb - root) / qa - 1e-12).astype(np.int64)
    t_hi = np.floor((-qb + root) / qa + 1e-12).astype(np.int64)
    t_lo = np.where(zero, np.maximum(t_lo, 1), t_lo)
    keep = ok & (t_hi >= t_lo)
    heads, t_lo, t_hi = heads[keep], t_lo[keep], t_hi[keep]
    if int((t_hi - t_lo + 1).sum()) > max_vectors:
        raise InvalidInputError(f"more than {max_vectors} wavevectors below k_max = {k_max}; "
                                "lower k_max")
    return recip, heads, t_lo, t_hi


def _expand(recip, heads, t_lo, t_hi, k_max):
    """Integer vectors n in head order, their k, and a mask of |k| <= k_max (round-off guard)."""
    counts = t_hi - t_lo + 1
    start = np.concatenate([[0], np.cumsum(counts)])
    head_of = np.repeat(np.arange(len(heads)), counts)
    t = np.arange(start[-1]) - start[head_of] + t_lo[head_of]
    n = np.concatenate([heads[head_of], t[:, None]], axis=1)
    k = _times_transpose(n, recip)
    return n, k, np.einsum("ij,ij->i", k, k) <= k_max * k_max * (1 + 1e-12)


def wavevectors(lattice, k_max: float, max_vectors: int = 5 * 10**7):
    """Integer vectors n (one of each +-n pair) with 0 < |2 pi L^-T n| <= k_max, and their k.

    Parameters
    ----------
    lattice : array_like, shape (d, d)
        The cell, lattice vectors as columns.
    k_max : float
        Largest |k|.
    max_vectors : int, default 5 * 10**7
        Refuse k_max values that need more wavevectors than this.

    Returns
    -------
    n : numpy.ndarray of int, shape (M, d)
        The integer vectors, grouped by (n_1 .. n_(d-1)).
    k : numpy.ndarray, shape (M, d)
        The wavevectors k = 2 pi L^-T n.

    Raises
    ------
    InvalidInputError
        If k_max is not a positive finite number or needs more than max_vectors wavevectors.
    """
    recip, heads, t_lo, t_hi = _heads(lattice, k_max, max_vectors)
    n, k, inside = _expand(recip, heads, t_lo, t_hi, k_max)
    return n[inside], k[inside]


@numba.njit(cache=True, parallel=True)
def _head_phases(cos_t, sin_t, lo, heads, out):
    """out[r] = Re, out[R + r] = Im of prod_a exp(-2 pi i h_a s_ja) for head r (tables hold
    cos and -sin of 2 pi n s for n = lo_a + index)."""
    n_rows, n_axes, m = heads.shape[0], heads.shape[1], cos_t.shape[2]
    for r in numba.prange(n_rows):
        if n_axes == 0:
            out[r, :] = 1.0
            out[n_rows + r, :] = 0.0
            continue
        i0 = heads[r, 0] - lo[0]
        out[r, :] = cos_t[0, i0, :]
        out[n_rows + r, :] = sin_t[0, i0, :]
        for a in range(1, n_axes):
            ia = heads[r, a] - lo[a]
            for j in range(m):
                re, im = out[r, j], out[n_rows + r, j]
                c, s = cos_t[a, ia, j], sin_t[a, ia, j]
                out[r, j] = re * c - im * s
                out[n_rows + r, j] = re * s + im * c


@numba.njit(cache=True)
def _scatter(pc, ps, block_t_lo, block_t_hi, block_start, rho_re, rho_im):
    """Add the block's modes: rho(h, +t) = sum a c(t), rho(h, -t) = sum a conj(c(t)).

    pc = [Re a; Im a] @ Re c, ps = [Re a; Im a] @ Im c (rows r and R + r for head r)."""
    n_rows = block_t_lo.size
    for r in range(n_rows):
        for t in range(block_t_lo[r], block_t_hi[r] + 1):
            c = abs(t)
            rr, ri = pc[r, c], ps[r, c]
            ir, ii = pc[n_rows + r, c], ps[n_rows + r, c]
            pos = block_start[r] + t - block_t_lo[r]
            if t >= 0:
                rho_re[pos] += rr - ii
                rho_im[pos] += ri + ir
            else:
                rho_re[pos] += rr + ii
                rho_im[pos] += ir - ri


def _density_modes(s, heads, t_lo, t_hi):
    """rho(n) = sum_j exp(-2 pi i n . s_j) for the vectors of :func:`_heads`, in head order.

    Exact direct sum: with a_j the phase of the head and c_j(t) = exp(-2 pi i t s_jd), the
    modes of one block of heads for all t follow from two real matrix products of
    [Re a; Im a] (2R x m) with Re c(t) and Im c(t) (m x (t_max + 1)).
    """
    n_particles, d = s.shape
    counts = t_hi - t_lo + 1
    start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    rho_re, rho_im = np.zeros(start[-1]), np.zeros(start[-1])
    span = np.maximum(np.abs(t_lo), np.abs(t_hi))
    order = np.argsort(span, kind="stable")  # similar |t| ranges share a block
    lo = heads.min(axis=0) if d > 1 else np.zeros(0, np.int64)
    hi = heads.max(axis=0) if d > 1 else np.zeros(0, np.int64)
    width = int((hi - lo).max()) + 1 if d > 1 else 1
    n_chunks = -(-n_particles // _PARTICLE_CHUNK)
    chunk = -(-n_particles // n_chunks)
    t_all = np.arange(int(span.max()) + 1)
    for p0 in range(0, n_particles, chunk):
        sc = s[p0:p0 + chunk]
        m = len(sc)
        cos_t = np.zeros((max(d - 1, 1), width, m))
        sin_t = np.zeros((max(d - 1, 1), width, m))
        for a in range(d - 1):
            ph = 2 * np.pi * np.outer(np.arange(lo[a], hi[a] + 1), sc[:, a])
            cos_t[a, :len(ph)], sin_t[a, :len(ph)] = np.cos(ph), -np.sin(ph)
        ph = 2 * np.pi * np.outer(sc[:, -1], t_all)
        last_re, last_im = np.cos(ph), -np.sin(ph)  # (m, t_max + 1)
        rows_per_block = max(1, _MATRIX_ELEMENTS // m)
        for b0 in range(0, len(order), rows_per_block):
            block = order[b0:b0 + rows_per_block]
            a_ph = np.empty((2 * len(block), m))
            _head_phases(cos_t, sin_t, lo, np.ascontiguousarray(heads[block]), a_ph)
            t_cols = int(span[block].max()) + 1
            pc, ps = a_ph @ last_re[:, :t_cols], a_ph @ last_im[:, :t_cols]
            _scatter(pc, ps, t_lo[block], t_hi[block], start[block], rho_re, rho_im)
    return rho_re + 1j * rho_im


def structure_factor_vectors(packing, k_max: float, max_vectors: int = 5 * 10**7):
    """S at every allowed wavevector with 0 < |k| <= k_max (one of each +-k pair).

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell.
    k_max : float
        Largest |k|.
    max_vectors : int, default 5 * 10**7
        Refuse k_max values that need more wavevectors than this.

    Returns
    -------
    n : numpy.ndarray of int, shape (M, d)
        The integer vectors of the wavevectors.
    k : numpy.ndarray, shape (M, d)
        The wavevectors k = 2 pi L^-T n.
    S : numpy.ndarray, shape (M,)
        S(k) = |sum_j exp(-i k.x_j)|^2 / N.

    Raises
    ------
    InvalidInputError
        If the packing is not hard spheres in a periodic cell, or k_max is not a positive finite
        number or needs more than max_vectors wavevectors.
    """
    packing.require_periodic_spheres("the structure analysis")
    recip, heads, t_lo, t_hi = _heads(packing.lattice, k_max, max_vectors)
    rho = _density_modes(packing.fractional(), heads, t_lo, t_hi)
    n, k, inside = _expand(recip, heads, t_lo, t_hi, k_max)
    s = (rho.real**2 + rho.imag**2) / packing.n_particles
    return n[inside], k[inside], s[inside]


def structure_factor(packing, k_max: float, shell_width: float | None = None) -> xr.Dataset:
    """Shell-averaged S(k) (module docstring).

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell.
    k_max : float
        Largest |k|.
    shell_width : float, optional
        Shell thickness; default 2 pi / V^(1/d).

    Returns
    -------
    xarray.Dataset
        On dim ``k`` (mean |k| of each non-empty shell): ``S`` (shell mean), ``S_err`` (standard
        error of the shell mean; NaN for a shell with one vector), ``n_vectors``, ``k_lo``, ``k_hi``.

    Raises
    ------
    InvalidInputError
        If the packing is not hard spheres in a periodic cell, k_max is not a positive finite
        number or needs too many wavevectors, shell_width is not positive and finite, or no allowed
        wavevector has |k| <= k_max.
    """
    _, kvec, s = structure_factor_vectors(packing, k_max)
    width = 2 * np.pi / packing.volume ** (1.0 / packing.dim) if shell_width is None else shell_width
    if not np.isfinite(width) or width <= 0:
        raise InvalidInputError(f"shell_width must be positive, got {shell_width!r}")
    if len(s) == 0:
        raise InvalidInputError(f"no allowed wavevector has |k| <= k_max = {k_max}; raise k_max")
    kmag = np.linalg.norm(kvec, axis=1)
    shell = np.floor(kmag / width).astype(np.int64)
    counts = np.bincount(shell)
    ids = np.flatnonzero(counts)
    counts = counts[ids]
    mean = np.bincount(shell, s)[ids] / counts
    sq = np.bincount(shell, s * s)[ids]
    var = np.where(counts > 1, (sq - counts * mean**2) / np.maximum(counts - 1, 1), np.nan)
    kmean = np.bincount(shell, kmag)[ids] / counts
    return xr.Dataset(
        data_vars=dict(S=("k", mean), S_err=("k", np.sqrt(np.maximum(var, 0) / counts)),
                       n_vectors=("k", counts), k_lo=("k", ids * width),
                       k_hi=("k", (ids + 1) * width)),
        coords=dict(k=kmean),
        attrs=dict(definition="S(k) = |sum_j exp(-i k.x_j)|^2 / N, k = 2 pi L^-T n, shell averages",
                   shell_width=width, n_particles=packing.n_particles),
    )


def extrapolate_s0(sk: xr.Dataset, k_fit: float, form: str = "linear"):
    """S(0) from a weighted fit of the shell means with k <= k_fit (module docstring).

    Parameters
    ----------
    sk : xarray.Dataset
        The result of :func:`structure_factor`.
    k_fit : float
        Largest shell |k| used in the fit.
    form : {"linear", "quadratic"}, default "linear"
        S0 + s1 k or S0 + s2 k^2.

    Returns
    -------
    S0 : float
        The fitted S(0).
    S0_err : float
        Its standard error, from the residual scatter.
    coefficients : numpy.ndarray
        (S0, s1) or (S0, s2).

    Raises
    ------
    InvalidInputError
        If form is not "linear" or "quadratic", or fewer than 3 shells have k <= k_fit.
    """
    powers = {"linear": (0, 1), "quadratic": (0, 2)}
    if form not in powers:
        raise InvalidInputError(f"form must be one of {sorted(powers)}, got {form!r}")
    sel = sk.k.values <= k_fit
    if sel.sum() < 3:
        raise InvalidInputError(
            f"only {int(sel.sum())} k-shells below k_fit = {k_fit}; at least 3 are needed "
            "(raise k_fit or use a larger system)")
    k, y = sk.k.values[sel], sk.S.values[sel]
    w = sk.n_vectors.values[sel].astype(float)
    x = np.stack([k**p for p in powers[form]], axis=1)
    sw = np.sqrt(w)
    coef, *_ = np.linalg.lstsq(x * sw[:, None], y * sw, rcond=None)
    resid = (y - x @ coef) * sw
    dof = max(len(y) - x.shape[1], 1)
    cov = np.linalg.inv((x * w[:, None]).T @ x) * float(resid @ resid) / dof
    return float(coef[0]), float(np.sqrt(cov[0, 0])), coef


def number_variance(packing, window_radii, n_windows: int = 10000, seed: int = 0) -> xr.Dataset:
    """sigma^2(R) of the number of centres in randomly placed spherical windows (module docstring).

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell.
    window_radii : array_like
        Window radii R (any shape; flattened and sorted).
    n_windows : int, default 10000
        Number of window centres, uniformly random in the cell.
    seed : int, default 0
        Seed of the window centres.

    Returns
    -------
    xarray.Dataset
        On dim ``R`` (ascending): ``variance``, ``variance_err`` (window sampling only), ``mean``
        and the ideal-gas reference ``variance_binomial`` = N p (1 - p), p = v_d R^d / V.

    Raises
    ------
    InvalidInputError
        If the packing is not hard spheres in a periodic cell, window_radii is empty or not all
        positive and finite, or n_windows < 2.
    """
    packing.require_periodic_spheres("the structure analysis")
    radii = np.sort(np.asarray(window_radii, dtype=float).ravel())
    if radii.size == 0 or not np.all(np.isfinite(radii)) or radii[0] <= 0:
        raise InvalidInputError("window_radii must be positive finite numbers")
    if int(n_windows) < 2:
        raise InvalidInputError(f"n_windows must be >= 2, got {n_windows}")
    rng = np.random.default_rng(seed)
    centres = rng.random((int(n_windows), packing.dim))
    grid = build_grid(packing.fractional(), packing.lattice, np.full(packing.n_particles, 0.5 * radii[-1]),
                      per_cell=2)
    counts = window_counts(centres, grid.x, grid.lattice, 1.0 / grid.heights, grid.n_cells, grid.strides,
                           grid.cell_offset, grid.cell_start, grid.order, radii).astype(float)
    m = counts.shape[0]
    mean = counts.mean(axis=0)
    dev2 = (counts - mean) ** 2
    p = ball_volume(radii, packing.dim) / packing.volume
    n = packing.n_particles
    return xr.Dataset(
        data_vars=dict(variance=("R", dev2.sum(axis=0) / (m - 1)),
                       variance_err=("R", dev2.std(axis=0, ddof=1) / math.sqrt(m)),
                       mean=("R", mean), variance_binomial=("R", n * p * (1 - p))),
        coords=dict(R=radii), attrs=dict(n_windows=m, seed=seed),
    )
