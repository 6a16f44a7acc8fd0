"""Benchmark of the SLP size ascent of ellipsoid packings (hardpack.jamming.ascent.ascend): CPU
seconds per LP step and in all, against the packing size, for the LP method the ascent picks
(HiGHS's dual simplex up to ``IPM_ABOVE`` particles, its interior-point method above) or a forced one.

Packings: a stored packing (default: the N = 80 M&M packing of the tests) tiled by ``--reps``, e.g.
2 2 2 for N = 640, which is how the 2026-11-29 measurements of ``docs/performance.md`` were made.

    python benchmarks/bench_ascent.py --reps 1 1 1
    python benchmarks/bench_ascent.py --reps 2 2 2 --steps 40
    python benchmarks/bench_ascent.py --reps 2 2 2 --method highs-ds --steps 1

Prints one line per LP (simplex or interior-point iterations, CPU seconds, the growth ds) and the
totals: CPU seconds, relative density gain, the smallest Perram-Wertheim factor before the final
shrink. Never part of the test suite.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from hardpack.io import dataset_to_packing, load_dataset
from hardpack.jamming import ascent

DEFAULT = Path(__file__).resolve().parents[1] / "tests" / "data" / "mm_n80_seed1_slow_p1e12.nc"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--packing", type=Path, default=DEFAULT, help="a stored ellipsoid packing")
    parser.add_argument("--reps", type=int, nargs="+", default=[1, 1, 1], help="tiling of the packing's cell")
    parser.add_argument("--steps", type=int, default=ascent.ASCENT_STEPS, help="LP steps of the schedule")
    parser.add_argument("--radius", type=float, default=1e-2, help="first trust radius")
    parser.add_argument("--method", choices=["highs-ds", "highs-ipm"], default=None,
                        help="force the LP method (default: the ascent's choice by N)")
    args = parser.parse_args()
    packing = dataset_to_packing(load_dataset(args.packing, kind="packing")).tiled(tuple(args.reps))
    method = args.method or ascent.lp_method(packing.n_particles)
    solve = ascent.solve_lp
    count = [0]

    def timed(c, **kwargs):
        kwargs["method"] = method
        start = time.process_time()
        res = solve(c, **kwargs)
        count[0] += 1
        print(f"LP {count[0]:3d}: {res.nit:6d} iterations, {time.process_time() - start:7.2f} CPU-s, "
              f"ds {res.x[-1]:.3e}", flush=True)
        return res

    ascent.solve_lp = timed
    print(f"N = {packing.n_particles}, phi = {packing.phi:.10f}, LP method {method}", flush=True)
    start = time.process_time()
    out = ascent.ascend(packing, radius=args.radius, steps=args.steps)
    print(f"{args.steps} steps: {time.process_time() - start:.1f} CPU-s, relative gain "
          f"{(out.phi - packing.phi) / packing.phi:.6e}, mu_min {out.mu_min:.15f}, repairs {out.repairs}")


if __name__ == "__main__":
    main()
