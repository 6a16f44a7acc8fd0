"""Timing of the packing model (not a test): constructing a sphere packing of N = 1e5 and its phi.

The configuration is an FCC crystal of N = 100 920 spheres (29 x 29 x 30 conventional cells)
shrunk by 1e-3 and jiggled, so that, as in a jammed packing, every sphere has 12 neighbours near
contact for the overlap check to examine. Reported: medians over repeats of

- ``Packing(x, r, L)``: validation and the overlap check (the cost every engine pays on output);
- ``Packing(..., allow_overlap=True)``: validation alone (the model's own overhead);
- ``phi`` and ``replace(radii=...)``.

Run it once with each version of the code to compare (the machine is shared: interleave runs)::

    PYTHONPATH=src python benchmarks/bench_packing.py [--repeats 7]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing


def configuration(seed: int = 0):
    fcc = lattice_packing("fcc", (29, 29, 30))
    rng = np.random.default_rng(seed)
    x = fcc.positions + rng.uniform(-2e-4, 2e-4, fcc.positions.shape)
    return x, np.full(fcc.n_particles, 0.5 * (1 - 1e-3)), np.array(fcc.lattice)


def median_time(func, repeats: int) -> float:
    func()  # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    x, r, lat = configuration()
    p = Packing(x, r, lat)
    print(f"N = {p.n_particles}, phi = {p.phi:.6f}")
    rows = {
        "Packing(x, r, L) with overlap check": lambda: Packing(x, r, lat),
        "Packing(x, r, L, allow_overlap=True)": lambda: Packing(x, r, lat, allow_overlap=True),
        "phi": lambda: p.phi,
        "replace(radii=...)": lambda: p.replace(radii=r),
    }
    for label, func in rows.items():
        print(f"{label:40s} {median_time(func, args.repeats) * 1e3:10.3f} ms")


if __name__ == "__main__":
    main()
