"""Building blocks of the BCMD event loop (hardpack.freeenergy._kernel) against brute force."""

import numpy as np
import pytest

from hardpack.events.heap import heap_set
from hardpack.freeenergy._kernel import wall_time


def test_heap_set_keeps_a_min_heap():
    # random inserts and key changes (up and down) of 50 items; after each, the 4-ary heap
    # property holds, hpos inverts heap, and the root is the smallest key
    rng = np.random.default_rng(1)
    n = 50
    hkey, heap, hpos = np.empty(n), np.empty(n, np.int64), np.full(n, -1, np.int64)
    keys = np.full(n, np.inf)
    size = 0
    for step in range(2000):
        i = int(rng.integers(n))
        key = float(rng.exponential()) if step % 7 else np.inf
        size = heap_set(hkey, heap, hpos, size, i, key)
        keys[i] = key
        assert np.all(hpos[heap[:size]] == np.arange(size))
        children = np.arange(1, size)
        assert np.all(hkey[(children - 1) // 4] <= hkey[children])
        np.testing.assert_array_equal(hkey[:size], keys[heap[:size]])
        assert hkey[0] == np.min(keys[hpos >= 0])


def brute_wall_time(dr, v, rho0, w, t_max=20.0, steps=1_000_001):
    """Last sign change of |dr + v t| - (rho0 + w t) from inside to outside on a fine grid."""
    t = np.linspace(0.0, t_max, steps)
    f = np.linalg.norm(dr + np.outer(t, v), axis=1) - (rho0 + w * t)
    out = np.flatnonzero((f[1:] > 0) & (f[:-1] <= 0))
    return t[out[0] + 1] if out.size else np.inf


@pytest.mark.parametrize("seed", range(4))
def test_wall_time_from_inside(seed):
    rng = np.random.default_rng(seed)
    dr = rng.normal(size=3) * 0.2
    v = rng.normal(size=3)
    t = wall_time(dr, v, 1.0, -0.05)
    assert t == pytest.approx(brute_wall_time(dr, v, 1.0, -0.05), abs=5e-5)


def test_wall_time_right_after_a_bounce():
    # a point exactly on the wall (|dr| = rho) moving inwards: the next hit is the later root
    # -2B/A, not 0 (the form hardpack.events.roots.exit_root uses cancels to 0 here); moving outwards: 0
    rho, w = 0.7, -0.01
    dr = np.array([rho, 0.0, 0.0])
    v = np.array([-0.8, 0.3, 0.0])
    b = dr @ v - rho * w
    a = v @ v - w * w
    assert wall_time(dr, v, rho, w) == pytest.approx(-2 * b / a, rel=1e-12)
    assert wall_time(dr, v, rho, w) == pytest.approx(brute_wall_time(dr, v, rho, w), abs=5e-5)
    assert wall_time(dr, -v, rho, w) == 0.0
