"""Benchmark of hardpack.jamming.verify on 3D LS packings (collective + strict tests).

Targets: N = 1000 in < 10 s (the dissertation's LOQO run took 1822 s for the
collective test alone, Donev 2006, Table 4.3) and N = 1e4 in
< 5 min. The machine has 2 shared cores, so each case is repeated and the median is quoted.

Packings: given files (``--packing``), or made with hardpack.md.compress (RSA at phi = 0.3,
Gamma = 1e-2 to a reduced pressure of 1e3, then ``--gamma`` to 1e12) and cached in ``--cache``.

    python benchmarks/bench_jamming.py --n 1000 --gamma 1e-4 --repeat 3
    python benchmarks/bench_jamming.py --packing a.nc b.nc --delta 1e-6
    python benchmarks/bench_jamming.py --packing n10000.nc --repeat 1 --method sequential --workers 2
    python benchmarks/bench_jamming.py --packing n1250.nc --tile 2 --method sequential  # scaling

A tiled packing is for scaling only: its tile^3 copies may move against each other, so a tiled
isostatic 3D packing is hypostatic (8 (3 N_b - 2) contacts against 3 (8 N_b - 1) degrees of
freedom for tile = 2: at least 13 floppy modes) and not collectively jammed.

Besides wall-clock medians it prints the CPU seconds of the process (the machine is shared: on a
loaded machine wall time can be several times the CPU time) and, per test, the number of LPs
and how many of them HiGHS solved (the others: the sparse-LU working set,
hardpack.jamming.workingset).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

from hardpack.io import dataset_to_packing, load_dataset
from hardpack.jamming import verify

STAGES = ("contacts", "local", "collective", "strict", "forces")


def make_packing(n: int, gamma: float, seed: int, cache: Path) -> Path:
    path = cache / f"ls3d_n{n}_seed{seed}_gamma{gamma:g}.nc"
    if path.exists():
        return path
    from hardpack.distributions import monodisperse
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, compress

    t0 = time.perf_counter()
    start = random_packing(n, 3, monodisperse(), 0.3, seed=seed)
    fast = compress(start, 1e-2, seed, StopCriteria(max_pressure=1e3))
    slow = compress(fast.packing, gamma, seed + 1, StopCriteria(max_pressure=1e12))
    cache.mkdir(parents=True, exist_ok=True)
    slow.save(path)
    print(f"generated {path} in {time.perf_counter() - t0:.0f} s")
    return path


def bench(path: Path, delta: float | None, repeat: int, seed: int, tile: int = 1,
          method: str = "ideal", workers: int = 1) -> dict:
    ds = load_dataset(path, kind="packing")
    packing = dataset_to_packing(ds, source=str(path)).tiled(tile)
    pressure = ds.attrs.get("Z")
    runs = []
    cpu = []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        r = verify(packing, delta=delta, seed=seed, md_pressure=pressure, method=method, workers=workers)
        total = time.perf_counter() - t0
        cpu.append(time.process_time() - c0)
        runs.append((total, r))
    r = runs[-1][1]
    med = {k: statistics.median(run.seconds.get(k, 0.0) for _, run in runs) for k in STAGES}
    med["total"] = statistics.median(t for t, _ in runs)
    med["total cpu"] = statistics.median(cpu)
    med["collective+strict"] = statistics.median(
        run.seconds.get("collective", 0) + run.seconds.get("strict", 0) for _, run in runs)
    return {"path": path, "n": packing.n_particles, "phi": packing.phi, "result": r, "seconds": med}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--packing", nargs="*", type=Path, default=[])
    ap.add_argument("--n", nargs="*", type=int, default=[])
    ap.add_argument("--gamma", type=float, default=1e-4, help="final LS growth rate")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--cache", type=Path, default=Path("benchmarks/data"))
    ap.add_argument("--delta", type=float, default=None,
                    help="contact-list tolerance (default: verify's, 1e-6 ideal / 0.1 sequential)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--method", default="ideal", choices=("ideal", "sequential"),
                    help="Algorithm 13 (ideal) or 14 (sequential random loading, for LS packings)")
    ap.add_argument("--tile", type=int, default=1,
                    help="verify the packing repeated tile^3 times (scaling only: not jammed, see above)")
    ap.add_argument("--workers", type=int, default=1,
                    help="sequential method: loading sequences run at once (one process each)")
    args = ap.parse_args(argv)
    paths = list(args.packing) + [make_packing(n, args.gamma, args.seed, args.cache) for n in args.n]
    for path in paths:
        b = bench(path, args.delta, args.repeat, args.seed, args.tile, args.method, args.workers)
        r, s = b["result"], b["seconds"]
        print(f"\n{path}: N={b['n']} phi={b['phi']:.4f}")
        print(r.summary())
        print("median seconds over", args.repeat, "runs: " + ", ".join(f"{k} {v:.2f}" for k, v in s.items()))
        for test in (r.collective_test, r.strict_test):
            if test is not None:
                highs = getattr(test, "n_lp_highs", None)
                print(f"{test.test}: {test.n_lp} LPs" + ("" if highs is None else f", {highs} by HiGHS"))
        print("load average:", " ".join(f"{x:.1f}" for x in os.getloadavg()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
