"""Timing of the structure analysis (not a test): medians over repeats after a warm-up call.

Targets: g2 of N = 1e5 in < 10 s; S(k) of N = 1e4 up to kD = 40 in < 30 s.
The configurations are uniform random points at the number density of a monodisperse packing
at phi = 0.64 (D = 1): the cost of both computations depends only on N, the number density and
the range, not on the positions being a real packing.

    python benchmarks/bench_structure.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from hardpack.distributions import monodisperse
from hardpack.geometry.packing import Packing
from hardpack.initial import random_packing
from hardpack.structure import (
    channel_radii,
    crystallinity,
    pair_correlation,
    regular_neighbours,
    structure_factor,
)


def points(n, phi=0.64, d=3, seed=0):
    length = (n * math.pi / 6 / phi) ** (1 / 3)
    rng = np.random.default_rng(seed)
    return Packing(rng.random((n, d)) * length, np.full(n, 0.5), np.eye(d) * length,
                   allow_overlap=True)


def timed(label, func, repeats):
    t0 = time.perf_counter()
    func()
    first = time.perf_counter() - t0
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        func()
        runs.append(time.perf_counter() - t0)
    print(f"{label:58s} median {statistics.median(runs):7.2f} s  "
          f"(runs {', '.join(f'{r:.2f}' for r in runs)}; first call incl. compile {first:.2f} s)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    big = points(100_000)
    timed("g2, N = 1e5, r_max = 5 D, dr = 0.005 D", lambda: pair_correlation(big, r_max=5.0),
          args.repeats)
    timed("g2, N = 1e5, r_max = 8 D, dr = 0.005 D", lambda: pair_correlation(big, r_max=8.0),
          args.repeats)
    mid = points(10_000)
    timed("S(k), N = 1e4, all allowed k with kD <= 40 (4.4e6 vectors)",
          lambda: structure_factor(mid, 40.0), args.repeats)
    rsa = random_packing(8192, 3, monodisperse(), 0.3, seed=1)
    timed("regular triangulation, N = 8192 (RSA phi = 0.3)", lambda: regular_neighbours(rsa),
          args.repeats)
    nl = regular_neighbours(rsa)
    timed("channel analysis on that triangulation", lambda: channel_radii(rsa, neighbours=nl),
          args.repeats)
    timed("q6 crystallinity on that triangulation", lambda: crystallinity(rsa, neighbours=nl),
          args.repeats)


if __name__ == "__main__":
    main()
