"""Benchmark of the first- and second-order jamming tests of ellipsoid packings
(hardpack.jamming.second_order.verify_ellipsoids, Donev 2006, Secs. 5.5.3 and 5.6).

Target: N = 1000 ellipsoids in < 60 s on one core (contacts from the gap distribution, local
tests with rattler removal, the collective test by the sparse projection on the floppy space;
with ``--refine``, the Newton refinement to the jamming point and the test there as well,
hardpack.jamming.refine).

Packings: given files (``--packing``), or made with ``hardpack init`` and ``hardpack compress``
(RSA at phi = 0.2 with semiaxes 1 : alpha^beta : alpha, growth rate 0.03 to Z = 1e3, then
``--gamma`` to Z = 1e12) and cached in ``--cache``; N = 1000 at gamma = 1e-2 takes ~25 min.

    python benchmarks/bench_ellipsoid_jamming.py --n 1000 --repeat 3
    python benchmarks/bench_ellipsoid_jamming.py --packing a.nc --repeat 1 [--refine]

Prints the wall-clock median, the CPU seconds of the process (the machine is shared: on a loaded
machine the wall time can be several times the CPU time), the seconds of each stage and the verdict.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

from hardpack.io import dataset_to_packing, load_dataset
from hardpack.jamming.refine import verify_at_jamming_point
from hardpack.jamming.second_order import verify_ellipsoids


def make_packing(n: int, alpha: float, beta: float, gamma: float, seed: int, cache: Path) -> Path:
    path = cache / f"ellipsoids_n{n}_a{alpha:g}_b{beta:g}_seed{seed}_gamma{gamma:g}.nc"
    if path.exists():
        return path
    from hardpack.cli import main

    cache.mkdir(parents=True, exist_ok=True)
    start = cache / f"init_{path.name}"
    t0 = time.perf_counter()
    main(["-q", "init", "--n", str(n), "--d", "3", "--phi", "0.2", "--semiaxes", "1", str(alpha**beta), str(alpha),
          "--seed", str(seed), "--out", str(start)])
    main(["-q", "compress", "--init", str(start), "--out", str(path), "--growth-rate", "0.03", "--final-growth-rate",
          str(gamma), "--switch-pressure", "1e3", "--max-pressure", "1e12", "--seed", str(seed)])
    print(f"generated {path} in {time.perf_counter() - t0:.0f} s")
    return path


def bench(path: Path, repeat: int, refine: bool = False) -> dict:
    packing = dataset_to_packing(load_dataset(path), allow_overlap=True)
    test = verify_at_jamming_point if refine else verify_ellipsoids
    verify_ellipsoids(packing, delta="gaps")  # compile the numba kernels, warm the caches
    walls, cpus = [], []
    for _ in range(repeat):
        cpu0, t0 = time.process_time(), time.perf_counter()
        result = test(packing, delta="gaps")
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - cpu0)
    return {"path": str(path), "N": packing.n_particles, "wall_median": statistics.median(walls),
            "cpu_median": statistics.median(cpus), "stages": result.seconds, "result": result}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--packing", nargs="+", type=Path, help="ellipsoid packing files")
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--alpha", type=float, default=1.5)
    parser.add_argument("--beta", type=float, default=1.0, help="0 prolate, 1 oblate (default)")
    parser.add_argument("--gamma", type=float, default=1e-2, help="final growth rate of a generated packing")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--cache", type=Path, default=Path(os.environ.get("TMPDIR", "/tmp")) / "hardpack_bench")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--refine", action="store_true", help="time verify_at_jamming_point instead")
    args = parser.parse_args(argv)
    paths = args.packing or [make_packing(args.n, args.alpha, args.beta, args.gamma, args.seed, args.cache)]
    for path in paths:
        out = bench(path, args.repeat, args.refine)
        res = out["result"]
        stages = ", ".join(f"{k} {v:.2f} s" for k, v in out["stages"].items())
        print(f"{out['path']}: N = {out['N']}, wall median {out['wall_median']:.2f} s, CPU {out['cpu_median']:.2f} s "
              f"({stages}); {res.params['method']}; verdict {res.verdict.name.lower()} at order {res.order}, "
              f"Z = {res.z_mean:.3f}, rattlers {int(res.rattler.sum())}, refined {res.params.get('refined', '-')}, "
              f"load {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
