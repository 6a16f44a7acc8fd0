"""Calls per second of the Perram-Wertheim contact function (hardpack.geometry.contact.pw_contact).

1e5 random pairs per dimension (aspect ratios up to 10, sizes over two decades, random orientations)
at relative distances within 5% of contact, evaluated from a numba loop: (a) with the initial guess
O_A / (O_A + O_B) of the bounding radii (Donev 2006, Sec. 2.2.2.1), (b) warm-started from the exact
maximiser (as an event-driven code reusing the previous lambda), plus the mean number of iterations
from 1/2. Rates are per second of process CPU time; medians over repeats.
Run: ``python benchmarks/bench_ellipsoid_contact.py [repeats]``.
"""

from __future__ import annotations

import statistics
import sys
import time

import numba
import numpy as np

from hardpack.geometry.contact import _pw_maximise, pw_contact, shape_inverse

N_PAIRS = 100_000


@numba.njit
def _sweep(r, a_inv, b_inv, lam0):
    total = 0.0
    for k in range(r.shape[0]):
        total += pw_contact(r[k], a_inv[k], b_inv[k], lam0[k])[0]
    return total


@numba.njit
def _solve(r, a_inv, b_inv):
    lam = np.empty(r.shape[0])
    iterations = np.empty(r.shape[0])
    for k in range(r.shape[0]):
        _, lam[k], _, iterations[k] = _pw_maximise(r[k], a_inv[k], b_inv[k], 0.5)
    return lam, iterations


def random_pairs(d, rng):
    """Separations within 5% of contact and X^-1 of both particles, and their bounding radii."""
    inv, bound = [], []
    for _ in range(2):
        axes = rng.uniform(1.0, 10.0, size=(N_PAIRS, d)) * 10.0 ** rng.uniform(-1, 1, size=(N_PAIRS, 1))
        out = np.empty((N_PAIRS, d, d))
        for k in range(N_PAIRS):
            q = rng.uniform(-np.pi, np.pi, 1) if d == 2 else rng.normal(size=4)
            shape_inverse(axes[k], q / np.linalg.norm(q) if d == 3 else q, out[k])
        inv.append(out)
        bound.append(axes.max(axis=1))
    u = rng.normal(size=(N_PAIRS, d))
    u /= np.linalg.norm(u, axis=1)[:, None]
    zeta = np.array([pw_contact(u[k], inv[0][k], inv[1][k], 0.5)[0] for k in range(N_PAIRS)])
    r = u / np.sqrt(zeta + 1)[:, None] * rng.uniform(0.95, 1.05, size=(N_PAIRS, 1))
    return r, inv[0], inv[1], bound[0] / (bound[0] + bound[1])


def rate(r, a_inv, b_inv, lam0, repeats):
    _sweep(r[:10], a_inv[:10], b_inv[:10], lam0[:10])
    times = []
    for _ in range(repeats):
        t = time.process_time()
        _sweep(r, a_inv, b_inv, lam0)
        times.append(time.process_time() - t)
    return N_PAIRS / statistics.median(times)


def main(repeats=5):
    rng = np.random.default_rng(0)
    for d in (2, 3):
        r, a_inv, b_inv, guess = random_pairs(d, rng)
        lam, iterations = _solve(r, a_inv, b_inv)
        print(f"d = {d}: bounding-radius guess {rate(r, a_inv, b_inv, guess, repeats):.3g} calls/s, "
              f"warm start {rate(r, a_inv, b_inv, lam, repeats):.3g} calls/s, "
              f"iterations from 1/2: mean {iterations.mean():.2f}, max {iterations.max():.0f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
