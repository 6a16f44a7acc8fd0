"""Micro-segregated labels (Donev 2006, sec. 13.5): the Matérn Gaussian random field, its level
cut and the window entropies, against closed forms (i.i.d. labels, periodic patterns, Markov-chain
rows, the field's exact second moments)."""

import math
from collections import Counter

import numpy as np
import pytest

from hardpack.errors import InvalidInputError
from hardpack.glass import segregated as seg
from hardpack.glass import thermo


def _h(p) -> float:
    p = np.asarray(p, dtype=float)
    p = p[p > 0]
    return float(-(p * np.log(p)).sum())


def _miller_madow_bias(a: int, b: int, n_windows: int) -> float:
    """|bias| of the plug-in s_{a,b} for i.i.d. fair-or-not binary sites with all configurations
    present: (K_{a,b} - K_{a-1,b} - K_{a,b-1} + K_{a-1,b-1}) / (2 N), K = 2^(sites)."""
    k = [[2 ** (i * j) if i and j else 1 for j in (b - 1, b)] for i in (a - 1, a)]
    return (k[1][1] - k[0][1] - k[1][0] + k[0][0]) / (2 * n_windows)


# --- window entropies ----------------------------------------------------------------------------

def test_iid_labels_give_the_mixing_entropy():
    # i.i.d. labels: S_{a,b} = a b h exactly, so s_{a,b} = h = s_mix for every window; the plug-in
    # estimate is off by the Miller-Madow bias and by the fluctuation of the site frequency
    # (first-order delta method: sd = sqrt(x (1 - x)) |ln((1 - x) / x)| / sqrt(N)).
    x, side = 1 / 3, 512
    n = side * side
    labels = (np.random.default_rng(7).random((side, side)) < x).astype(np.int8)
    s = seg.markov_entropy(seg.block_entropies(labels, 3, 3))
    h = thermo.mixing_entropy(x)
    assert round(h, 4) == 0.6365
    sd = math.sqrt(x * (1 - x)) * abs(math.log((1 - x) / x)) / math.sqrt(n)
    for a in range(1, 4):
        for b in range(1, 4):
            assert abs(s[a - 1, b - 1] - h) < _miller_madow_bias(a, b, n) + 5 * sd, (a, b)


def test_constant_labels_have_zero_entropy():
    for value in (0, 1):
        labels = np.full((8, 9), value, dtype=np.int8)
        S = seg.block_entropies(labels, 4, 4)
        assert np.all(S == 0.0)
        assert np.all(seg.markov_entropy(S) == 0.0)


def _substring_entropy(word, length: int) -> float:
    """Entropy of the cyclic substrings of ``word`` of a given length, one per phase."""
    p = len(word)
    counts = Counter(tuple(word[(k + i) % p] for i in range(length)) for k in range(p))
    return _h(np.array(list(counts.values())) / p)


def test_stripes_along_one_axis():
    # labels constant down the columns, the word repeated along each row: a window's content is a
    # substring of length b, so S_{a,b} = g(b) for every a >= 1; s_{a,b} = 0 for a >= 2, and
    # s_{1,b} = g(b) - g(b - 1) vanishes once b exceeds the period
    word = [1, 1, 0, 1, 0, 0, 0]
    p = len(word)
    labels = np.tile(np.array(word, dtype=np.int8), (5, 3))  # 5 x 21
    S = seg.block_entropies(labels, 3, p + 2)
    g = [0.0] + [_substring_entropy(word, b) for b in range(1, p + 3)]
    for a in range(1, 4):
        assert S[a] == pytest.approx(g, abs=1e-12)
    s = seg.markov_entropy(S)
    assert np.all(np.abs(s[1:]) < 1e-12)
    assert s[0] == pytest.approx(np.diff(g), abs=1e-12)
    assert np.all(np.abs(s[:, p:]) < 1e-12)
    assert g[-1] == pytest.approx(math.log(p))
    # the same pattern transposed swaps the window's axes
    St = seg.block_entropies(labels.T, p + 2, 3)
    assert St == pytest.approx(S.T, abs=1e-12)


def test_diagonal_stripes():
    # labels w[(i + j) mod 3], w = 100: an a x b window holds the substring of length a + b - 1,
    # so S_{a,b} = g(a + b - 1) with g(1) = s_mix(1/3) and g(>= 2) = ln 3
    word = [1, 0, 0]
    i, j = np.indices((9, 12))
    labels = np.array(word, dtype=np.int8)[(i + j) % 3]
    S = seg.block_entropies(labels, 4, 4)
    g = {k: _substring_entropy(word, k) for k in range(1, 8)}
    assert g[1] == pytest.approx(thermo.mixing_entropy(1 / 3))
    for a in range(1, 5):
        for b in range(1, 5):
            assert S[a, b] == pytest.approx(g[a + b - 1], abs=1e-12)
    s = seg.markov_entropy(S)
    # 2 x 2: g(3) - 2 g(2) + g(1) = s_mix - ln 3 < 0 (the Markov estimate is not an entropy)
    assert s[1, 1] == pytest.approx(thermo.mixing_entropy(1 / 3) - math.log(3))
    for a in range(2, 5):
        for b in range(2, 5):
            if a + b - 3 >= 2:
                assert abs(s[a - 1, b - 1]) < 1e-12


def test_periodic_tile_has_zero_entropy_beyond_its_size():
    # a random p x q tile repeated: windows with more rows than p and more columns than q see a
    # whole tile, identify its phase (the tile has no smaller period), S = ln(p q) and s = 0
    p, q = 3, 4
    tile = np.array([[1, 0, 0, 1], [0, 0, 1, 1], [1, 0, 0, 0]], dtype=np.int8)
    labels = np.tile(tile, (4, 3))
    S = seg.block_entropies(labels, p + 2, q + 2)
    assert S[p:, q:] == pytest.approx(math.log(p * q), abs=1e-12)
    s = seg.markov_entropy(S)
    assert np.all(np.abs(s[p:, q:]) < 1e-12)
    assert s[0, 0] == pytest.approx(_h([tile.mean(), 1 - tile.mean()]))


def _cyclic_markov_rows(P, rows: int, length: int, rng) -> np.ndarray:
    """Rows drawn from the cyclic two-state Markov measure prod_j P[x_j, x_{j+1 mod L}] / tr P^L,
    translation invariant on the ring; its window marginals are the stationary chain's up to
    O(lambda_2^(L - window))."""
    powers = [np.eye(2)]
    for _ in range(length):
        powers.append(powers[-1] @ P)
        powers[-1] /= powers[-1].sum() / 2  # rescaling cancels in every ratio below
    x = np.empty((rows, length), dtype=np.int8)
    first = np.diag(powers[length]) / np.trace(powers[length])
    x[:, 0] = rng.random(rows) < first[1]
    x0 = x[:, 0]
    for j in range(length - 1):
        rest = powers[length - 1 - j]
        w1 = P[x[:, j], 1] * rest[1, x0]
        w0 = P[x[:, j], 0] * rest[0, x0]
        x[:, j + 1] = rng.random(rows) < w1 / (w0 + w1)
    return x


def test_markov_chain_rows_give_the_entropy_rate():
    # rows: independent copies of a stationary binary Markov chain (transition matrix P) along the
    # columns. S_{a,b} = a [H(pi) + (b - 1) h], so s_{a,1} = H(pi) and s_{a,b} = h for b >= 2, with
    # the entropy rate h = sum_i pi_i H(P_i.). Tolerance: Miller-Madow bias bound + 5 standard
    # errors of the mean over independent lattices.
    P = np.array([[0.9, 0.1], [0.2, 0.8]])
    pi = np.array([2 / 3, 1 / 3])
    assert pi @ P == pytest.approx(pi)
    h_rate = sum(pi[i] * _h(P[i]) for i in range(2))
    h_pi = _h(pi)
    rng = np.random.default_rng(11)
    rows, length, reps = 128, 2048, 6
    estimates = []
    for _ in range(reps):
        labels = _cyclic_markov_rows(P, rows, length, rng)
        estimates.append(seg.markov_entropy(seg.block_entropies(labels, 3, 3)))
        # the chain along the other axis: the window's rows and columns swap roles
        if len(estimates) == 1:
            swapped = seg.markov_entropy(seg.block_entropies(labels.T, 3, 3))
            assert swapped == pytest.approx(estimates[0].T, abs=1e-12)
    est = np.array(estimates)
    mean, se = est.mean(axis=0), est.std(axis=0, ddof=1) / math.sqrt(reps)
    expected = np.array([[h_pi, h_rate, h_rate]] * 3)
    n = rows * length
    for a in range(1, 4):
        for b in range(1, 4):
            tol = _miller_madow_bias(a, b, n) + 5 * se[a - 1, b - 1]
            assert abs(mean[a - 1, b - 1] - expected[a - 1, b - 1]) < tol, (a, b)
    assert h_rate < h_pi - 0.2  # the test separates the rate from the single-site entropy


def test_windows_pool_realisations_and_refuse_bad_input():
    rng = np.random.default_rng(0)
    stack = (rng.random((3, 6, 7)) < 0.4).astype(np.int8)
    codes = seg.window_codes(stack, 2, 3)
    assert codes.shape == (3, 6, 7)
    # bit i m + j is the label at offset (i, j)
    r, c = 4, 5
    expected = sum(int(stack[1, (r + i) % 6, (c + j) % 7]) << (i * 3 + j) for i in range(2) for j in range(3))
    assert codes[1, r, c] == expected
    pooled = Counter(codes.ravel().tolist())
    p = np.array(list(pooled.values())) / codes.size
    assert seg.block_entropy(stack, 2, 3) == pytest.approx(_h(p), abs=1e-12)
    assert seg.block_entropy(stack, 0, 3) == 0.0
    with pytest.raises(InvalidInputError, match="does not fit"):
        seg.block_entropy(stack, 7, 2)
    with pytest.raises(InvalidInputError, match="0 .A. or 1"):
        seg.block_entropy(stack + 1, 2, 2)
    with pytest.raises(InvalidInputError, match="more than 62"):
        seg.window_codes(np.zeros((8, 8), dtype=np.int8), 8, 8)


# --- the Matérn field and its level cut ----------------------------------------------------------

def test_matern_parametrisation():
    r = np.linspace(0, 10, 41)
    # nu = 1/2: the exponential correlation exp(-r / R)
    assert seg.matern(r, 2.5, 0.5) == pytest.approx(np.exp(-r / 2.5), rel=1e-12)
    # C(0) = 1 and C decreasing in r, increasing in R and in nu at fixed r > 0
    c = seg.matern(r, 3.0, 0.3)
    assert c[0] == 1.0 and np.all(np.diff(c) < 0)
    assert np.all(seg.matern(r[1:], 4.0, 0.3) > c[1:])
    assert np.all(seg.matern(r[1:], 3.0, 0.4) > c[1:])
    for bad in ((0.0, 0.3), (-1.0, 0.3), (2.0, 0.0), (2.0, 1.0), (2.0, float("nan"))):
        with pytest.raises(InvalidInputError):
            seg.matern(r, *bad)


def _second_moment_variance(cov: np.ndarray, lag) -> float:
    """Exact variance of (1/N) sum_x f(x) f(x + lag) for a zero-mean Gaussian field on a torus with
    covariance ``cov`` (Isserlis): (1/N) sum_s [C(s)^2 + C(s + lag) C(s - lag)]."""
    plus = np.roll(cov, (-lag[0], -lag[1]), axis=(0, 1))
    minus = np.roll(cov, lag, axis=(0, 1))
    return float((cov**2 + plus * minus).sum() / cov.size)


@pytest.mark.parametrize("R, nu", [(1.0, 0.1), (3.0, 0.3), (5.0, 0.5)])
def test_field_has_the_matern_covariance(R, nu):
    shape, seeds = (64, 64), 40
    cov = seg.torus_covariance(shape, R, nu)
    lam, clipped = seg.circulant_spectrum(shape, R, nu)
    assert clipped == 0.0 and lam.mean() == pytest.approx(1.0, rel=1e-12)
    fields = np.stack([seg.gaussian_field(shape, R, nu, s).values for s in range(seeds)])
    for lag in [(0, 0), (0, 1), (1, 0), (1, 1), (0, 2), (2, 1), (0, 4), (3, 3), (0, 8)]:
        est = (fields * np.roll(fields, (-lag[0], -lag[1]), axis=(1, 2))).mean()
        se = math.sqrt(_second_moment_variance(cov, lag) / seeds)
        exact = float(seg.matern(math.hypot(*lag), R, nu))
        assert exact == pytest.approx(cov[lag], rel=1e-12)
        assert abs(est - exact) < 4 * se, (lag, est, exact, se)
    # unit variance: lag (0, 0) above; the field has zero mean up to its own standard error
    assert abs(fields.mean()) < 4 * math.sqrt(cov.mean() / seeds)


def test_same_seed_same_field():
    a = seg.gaussian_field((16, 24), 2.0, 0.3, 5).values
    b = seg.gaussian_field((16, 24), 2.0, 0.3, 5).values
    c = seg.gaussian_field((16, 24), 2.0, 0.3, 6).values
    assert a.shape == (16, 24)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    labels, fields, _ = seg.label_ensemble((16, 24), 2.0, 0.3, 2 / 3, 5, count=3)
    assert np.array_equal(fields[0], a) and labels.shape == (3, 16, 24)
    again, _, _ = seg.label_ensemble((16, 24), 2.0, 0.3, 2 / 3, 5, count=3)
    assert np.array_equal(labels, again)


def test_clipped_spectrum_is_reported():
    # a correlation length comparable to the lattice: the minimum-image covariance is not
    # positive definite; the weight of the clipped eigenvalues is reported, not hidden
    lam, clipped = seg.circulant_spectrum((16, 16), 20.0, 0.9)
    assert clipped > 0 and np.all(lam >= 0)
    assert seg.gaussian_field((16, 16), 20.0, 0.9, 1).clipped_weight == clipped


@pytest.mark.parametrize("shape, fraction", [((64, 64), 2 / 3), ((7, 5), 2 / 3), ((3, 3), 0.5), ((10, 1), 0.05)])
def test_level_cut_count(shape, fraction):
    field = seg.gaussian_field(shape, 1.5, 0.4, 3).values
    labels = seg.level_cut(field, fraction)
    n_a = int((labels == seg.LABEL_A).sum())
    assert n_a == math.floor(fraction * field.size + 0.5) == seg.count_a(field.size, fraction)
    if 0 < n_a < field.size:
        assert field[labels == seg.LABEL_A].min() > field[labels == seg.LABEL_B].max()


def test_level_cut_breaks_ties_in_row_major_order():
    labels = seg.level_cut(np.zeros((3, 4)), 0.5)
    assert labels.ravel().tolist() == [0] * 6 + [1] * 6
    assert round(2 / 3 * 4096) == seg.count_a(4096, 2 / 3) == 2731
    for bad in (0.0, 1.0, -0.1, float("nan")):
        with pytest.raises(InvalidInputError, match="fraction of A sites"):
            seg.level_cut(np.zeros((3, 4)), bad)


def test_entropy_decreases_with_correlation_length_and_smoothness():
    # Donev 2006, sec. 13.5 and Figs. 13.16-13.17: increasing R or nu increases the clustering and
    # lowers the entropy per site. s_{3,3} (plug-in bias < 2e-3 here) pooled over 16 fields of
    # 64 x 64 for R = 1..5 and nu = 0.1, 0.3, 0.5
    table = np.empty((3, 5))
    for i, nu in enumerate((0.1, 0.3, 0.5)):
        for j, R in enumerate(range(1, 6)):
            labels, _, _ = seg.label_ensemble((64, 64), R, nu, 2 / 3, 100 + j, count=16)
            table[i, j] = seg.markov_entropy(seg.block_entropies(labels, 3, 3))[2, 2]
    assert np.all(np.diff(table, axis=1) < 0), table
    assert np.all(np.diff(table, axis=0) < 0), table
    assert np.all(table < thermo.mixing_entropy(1 / 3))


# --- the study dataset, the labelled crystal and the command line --------------------------------

def test_label_study_tables():
    ds = seg.label_study((32, 48), 2.0, 0.4, 2 / 3, 9, count=3, window=(3, 2))
    labels = ds["labels"].values
    assert labels.shape == (3, 32, 48) and ds.attrs["n_windows"] == 3 * 32 * 48
    assert ds.attrs["n_a"] == round(2 / 3 * 32 * 48)
    assert np.all((labels == seg.LABEL_A).sum(axis=(1, 2)) == ds.attrs["n_a"])
    S = seg.block_entropies(labels, 3, 2)
    assert ds["block_entropy"].values == pytest.approx(S[1:, 1:], abs=1e-15)
    assert ds["entropy_per_site"].values == pytest.approx(seg.markov_entropy(S), abs=1e-15)
    assert ds["entropy_per_site"].sel(window_rows=1, window_cols=1) == pytest.approx(ds.attrs["s_mix"])
    assert ds["n_configurations"].sel(window_rows=1, window_cols=1) == 2
    assert np.all(ds["n_configurations"].values <= 2 ** np.outer(np.arange(1, 4), np.arange(1, 3)))
    for a in range(1, 4):
        for b in range(1, 3):
            seen = np.unique(seg.window_codes(labels, a, b)).size
            assert ds["n_configurations"].sel(window_rows=a, window_cols=b) == seen


def test_labelled_crystal_carries_the_labels():
    labels = seg.label_ensemble((8, 6), 1.5, 0.3, 2 / 3, 4)[0][0]
    p = seg.labelled_crystal(labels, 0.8)
    assert p.n_particles == 48 and np.all(p.radii == p.radii[0]) and p.phi == pytest.approx(0.8)
    # site (r, c) sits at (c + (r mod 2) / 2, r sqrt(3) / 2) + 1/4 and carries labels[r, c]
    r, c = np.indices((8, 6))
    site = np.column_stack([c.ravel() + 0.5 * (r.ravel() % 2), r.ravel() * math.sqrt(3) / 2]) + 0.25
    order = np.lexsort((p.positions[:, 0], np.round(p.positions[:, 1], 9)))
    assert p.positions[order] == pytest.approx(site, abs=1e-12)
    assert np.array_equal(p.species[order], labels.ravel())
    with pytest.raises(InvalidInputError, match="even number"):
        seg.labelled_crystal(labels[:7], 0.8)


def test_cli_writes_labels_and_crystal(tmp_path, capsys):
    from hardpack.cli import main
    from hardpack.io import load_dataset, load_packing

    out = tmp_path / "labels.nc"
    assert main(["glass-labels", "--shape", "16", "20", "--R", "2", "--nu", "0.3", "--seed", "3",
                 "--realisations", "2", "--window", "3", "3", "--out", str(out)]) == 0
    ds = load_dataset(out, kind="glass_labels")
    ref = seg.label_study((16, 20), 2.0, 0.3, 2 / 3, 3, count=2, window=(3, 3))
    assert np.array_equal(ds["labels"].values, ref["labels"].values)
    assert ds["entropy_per_site"].values == pytest.approx(ref["entropy_per_site"].values, abs=1e-15)
    assert ds.attrs["seed"] == 3 and "git_commit" in ds.attrs and ds.attrs["matern_convention"]
    crystal = tmp_path / "crystal.nc"
    assert main(["glass-labelled-crystal", "--labels", str(out), "--realisation", "1", "--phi", "0.7",
                 "--out", str(crystal)]) == 0
    p = load_packing(crystal)
    assert sorted(p.species.tolist()) == sorted(ds["labels"].values[1].ravel().tolist())


@pytest.mark.parametrize("extra, message", [
    (["--R", "0", "--nu", "0.3"], "correlation length R must be > 0"),
    (["--R", "-2", "--nu", "0.3"], "correlation length R must be > 0"),
    (["--R", "2", "--nu", "1"], "smoothness nu must be in (0, 1)"),
    (["--R", "2", "--nu", "0"], "smoothness nu must be in (0, 1)"),
    (["--R", "2", "--nu", "0.3", "--fraction-a", "1.5"], "fraction of A sites must be in (0, 1)"),
    (["--R", "2", "--nu", "0.3", "--fraction-a", "0"], "fraction of A sites must be in (0, 1)"),
    (["--R", "2", "--nu", "0.3", "--shape", "3", "64"], "a 4 x 4 window does not fit the 3 x 64 lattice"),
    (["--R", "2", "--nu", "0.3", "--window", "0", "2"], "window sizes must be >= 1"),
    (["--R", "2", "--nu", "0.3", "--realisations", "0"], "--realisations must be >= 1"),
])
def test_cli_refuses_bad_input(tmp_path, capsys, extra, message):
    from hardpack.cli import main

    out = tmp_path / "x.nc"
    assert main(["glass-labels", "--seed", "1", "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err
    assert not out.exists()
