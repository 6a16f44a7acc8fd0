"""Benchmark of the hard-ellipsoid / hard-ellipse event-driven MD (hardpack.md.ellipsoid): collisions
per second of equilibrium (NVE) fluids, prolate against oblate. Prints a table; never part of the
test suite.

    python benchmarks/bench_ellipsoids.py                 # N = 1e4, 3D and 2D, alpha = 1.5
    python benchmarks/bench_ellipsoids.py --n 2000 --windows 3
    python benchmarks/bench_ellipsoids.py --alphas 1.1 1.5 2.0 2.5   # rates vs aspect ratio

Each configuration: RSA at phi = 0.2 (hardpack.initial.random_ellipsoid_packing), a fast LS
compression (Gamma = 0.3) to the target phi, a warm-up window that lets the adaptive neighbour shell
settle, then timed NVE windows of 5 N collisions (numba compilation excluded: the kernels are
cached and a small run compiles first). Reported: wall-clock and CPU-time collision rates (the
machine may be shared), contact-function evaluations per collision, events per collision.
Targets (of the task): >= 1e5 collisions/s for ellipsoids and >= 3e5/s for ellipses on one core.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hardpack.initial import random_ellipsoid_packing
from hardpack.md import StopCriteria, maxwell_boltzmann
from hardpack.md.ellipsoid import EllipsoidSimulation, compress_ellipsoids, random_angular_velocities
from hardpack.md.ellipsoid_engine import moments_of_inertia

#: target volume fractions of the timed fluids (well below the isotropic-nematic / jamming regime)
PHI = {2: 0.6, 3: 0.45}


def semiaxes(d: int, alpha: float, kind: str) -> list[float]:
    """Spheroid semiaxes: prolate (alpha, 1, 1), oblate (1, alpha, alpha); ellipses (alpha, 1)."""
    if d == 2:
        return [alpha, 1.0]
    return [alpha, 1.0, 1.0] if kind == "prolate" else [1.0, alpha, alpha]


def run(d: int, n: int, alpha: float, kind: str, windows: int, seed: int = 1) -> dict:
    packing = random_ellipsoid_packing(n, semiaxes(d, alpha, kind), 0.2, seed=seed)
    packing = compress_ellipsoids(packing, 0.3, seed, stop=StopCriteria(max_pressure=None, target_phi=PHI[d])).packing
    inertia = moments_of_inertia(packing.shape.semiaxes)
    sim = EllipsoidSimulation(packing, maxwell_boltzmann(n, d, seed),
                              random_angular_velocities(n, d, inertia, seed + 1), 0.0)
    sim.engine.rescale_velocities(1.0)
    for _ in range(2):
        sim.run_window(2 * n)
    c0, e0 = sim.collisions, sim.events
    evals = 0
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(windows):
        sim.run_window(5 * n)
        evals += sim.engine.last_evaluations
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    coll = sim.collisions - c0
    return {"d": d, "N": n, "alpha": alpha, "kind": kind, "phi": sim.phi(), "collisions": coll,
            "rate_wall": coll / wall, "rate_cpu": coll / cpu, "evals_per_coll": evals / coll,
            "events_per_coll": (sim.events - e0) / coll, "Z": float(np.mean(sim.records["Z"][-windows:]))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--alphas", type=float, nargs="+", default=[1.5],
                        help="aspect ratios (one table row per shape and alpha)")
    parser.add_argument("--kinds", nargs="+", default=["prolate", "oblate", "ellipse"],
                        choices=["prolate", "oblate", "ellipse"])
    parser.add_argument("--windows", type=int, default=4)
    args = parser.parse_args()
    run(2, 64, 1.5, "prolate", 1)  # compile (or load the numba cache)
    run(3, 64, 1.5, "prolate", 1)
    print(f"{'d':>2} {'N':>6} {'alpha':>5} {'kind':>8} {'phi':>6} {'Z':>7} {'coll/s wall':>12} "
          f"{'coll/s cpu':>11} {'evals/coll':>10} {'events/coll':>11}")
    for kind in args.kinds:
        for alpha in args.alphas:
            r = run(2 if kind == "ellipse" else 3, args.n, alpha, kind, args.windows)
            print(f"{r['d']:>2} {r['N']:>6} {r['alpha']:>5} {r['kind']:>8} {r['phi']:>6.3f} {r['Z']:>7.3f} "
                  f"{r['rate_wall']:>12.4g} {r['rate_cpu']:>11.4g} {r['evals_per_coll']:>10.1f} "
                  f"{r['events_per_coll']:>11.2f}", flush=True)


if __name__ == "__main__":
    main()
