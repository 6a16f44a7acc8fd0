"""Benchmark of the event-driven MD engine (hardpack.md): collision rates, time to jam, compile
time and peak memory. Prints tables; never part of the test suite.

    python benchmarks/bench_md.py            # full: d = 2..6, N = 1e3..1e5, 3 repeats
    python benchmarks/bench_md.py --quick    # d = 2..4, N = 1e3..1e4, 1 repeat
    python benchmarks/bench_md.py --only poly --repeats 5   # one section

Every configuration runs in its own subprocess (clean peak-memory figure, no cross-talk).
Rates are medians over repeats of wall-clock collisions per second; the machine may be shared, so
the CPU-time rate is printed too.

1. Equilibrium fluid rate: NVE (Gamma = 0) at phi = 0.6 phi_J(d) (phi_J = 0.82, 0.64, 0.46,
   0.31, 0.20 for d = 2..6), prepared by RSA plus a fast compression; timed windows of 5 N
   collisions after a warm-up that lets the adaptive neighbour shell settle (:func:`warm_up`).
2. Time to jam: N = 1e4 monodisperse spheres in 3D from RSA at phi = 0.1, Gamma = 0.02, until
   Z = 1e12 (numba compilation excluded: a small run compiles first), plus the collision rate in
   the dense part of the run (Z >= 1e3).
3. Compile time: first call of the engine in a fresh process with an empty numba cache.
4. Wide size distribution: NVE rate of N = 1e4 spheres in 3D with radii uniform in volume
   over a factor omega = 10 (hardpack.distributions.uniform_volume(10), several grid levels) against
   monodisperse spheres, both at phi = 0.5.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

PHI_J = {2: 0.82, 3: 0.64, 4: 0.46, 5: 0.31, 6: 0.20}
RSA_START = {2: 0.33, 3: 0.23, 4: 0.15, 5: 0.10, 6: 0.066}


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def warm_up(sim, n: int, max_windows: int = 24) -> None:
    """Compile, then run windows of 2 N collisions until the adaptive neighbour shell has stayed
    unchanged for two windows, so the timed windows see the lists a long run settles on (the
    shell moves by one factor SHELL_STEP per window, and lists follow it within a window)."""
    steady = 0
    for _ in range(max_windows):
        shell = sim.shell
        sim.run_window(2 * n)
        steady = steady + 1 if sim.shell == shell else 0
        if steady >= 2:
            return


def worker_rate(d: int, n: int, repeats: int, phi: float | None = None, omega: float = 1.0) -> dict:
    import numpy as np

    from hardpack.distributions import monodisperse, uniform_volume
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, compress
    from hardpack.md.simulation import Simulation, maxwell_boltzmann

    phi = 0.6 * PHI_J[d] if phi is None else phi
    dist = monodisperse(0.5) if omega == 1.0 else uniform_volume(omega)
    packing = random_packing(n, d, dist, min(phi, RSA_START[d]), seed=1)
    t0 = time.perf_counter()
    if phi > packing.phi:
        packing = compress(packing, 0.1, 1, stop=StopCriteria(max_pressure=None, target_phi=phi)).packing
    prep = time.perf_counter() - t0
    sim = Simulation(packing, maxwell_boltzmann(n, d, 2), 0.0)
    warm_up(sim, n)
    wall, cpu = [], []
    for _ in range(repeats):
        c0, w0, p0 = sim.collisions, time.perf_counter(), time.process_time()
        rec = sim.run_window(5 * n)
        wall.append((sim.collisions - c0) / (time.perf_counter() - w0))
        cpu.append((sim.collisions - c0) / (time.process_time() - p0))
    return {"d": d, "n": n, "phi": phi, "omega": omega, "rate": float(np.median(wall)),
            "cpu_rate": float(np.median(cpu)), "Z": rec["Z"], "neighbours": rec["neighbours"],
            "shell": rec["shell"], "levels": int(sim.engine.ncl.shape[0]), "prep_s": prep,
            "peak_mb": _peak_mb()}


def worker_jam(n: int, growth_rate: float) -> dict:
    import numpy as np

    from hardpack.distributions import monodisperse
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, compress

    compress(random_packing(300, 3, monodisperse(0.5), 0.1, seed=9), growth_rate, 0,
             stop=StopCriteria(max_collisions=5000))  # compile outside the timing
    packing = random_packing(n, 3, monodisperse(0.5), 0.1, seed=1)
    w0, p0 = time.perf_counter(), time.process_time()
    res = compress(packing, growth_rate, 3, stop=StopCriteria(max_pressure=1e12))
    wall, cpu = time.perf_counter() - w0, time.process_time() - p0
    ts = res.timeseries
    dense = np.flatnonzero(ts.Z.values >= 1e3)
    k = dense[0] - 1 if len(dense) and dense[0] > 0 else 0
    dense_coll = ts.collisions.values[-1] - ts.collisions.values[k]
    dense_wall = ts.wall_time.values[-1] - ts.wall_time.values[k]
    return {"n": n, "growth_rate": growth_rate, "wall_s": wall, "cpu_s": cpu, "phi": res.stats["phi"],
                "Z": res.stats["Z"], "collisions": res.stats["collisions"],
                "rate": res.stats["collisions"] / wall, "dense_rate": float(dense_coll / dense_wall),
                "peak_mb": _peak_mb()}


def worker_compile(d: int) -> dict:
    from hardpack.distributions import monodisperse
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, compress

    packing = random_packing(200, d, monodisperse(0.5), 0.05, seed=1)
    t0 = time.perf_counter()
    compress(packing, 0.1, 0, stop=StopCriteria(max_collisions=2000))
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    compress(packing, 0.1, 0, stop=StopCriteria(max_collisions=2000))
    second = time.perf_counter() - t0
    return {"d": d, "compile_s": first - second}


def _run(args: list[str], env=None, timeout: float = 1800.0) -> dict:
    try:
        out = subprocess.run([sys.executable, __file__, "--worker", *map(str, args)],
                             capture_output=True, text=True, env=env, check=False, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timed out after {timeout:.0f} s"}
    if out.returncode != 0:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr.strip() else "failed"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def section_compile(quick: bool, repeats: int) -> None:
    print("\n## Compile time (fresh numba cache)")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for d in (3,) if quick else (2, 3, 4):
            r = _run(["compile", d], env=env)
            print(f"d = {d}: {r.get('compile_s', float('nan')):.1f} s {r.get('error', '')}")


def section_fluid(quick: bool, repeats: int) -> None:
    dims = (2, 3, 4) if quick else (2, 3, 4, 5, 6)
    sizes = (1000, 10000) if quick else (1000, 10000, 100000)
    print("\n## Equilibrium fluid at phi = 0.6 phi_J(d): collisions per second (median of "
          f"{repeats}), peak memory")
    print("| d | N | phi | Z | coll/s (wall) | coll/s (CPU) | neighbours | peak MB |")
    print("|---|---|---|---|---|---|---|---|")
    for d in dims:
        for n in sizes:
            r = _run(["rate", d, n, repeats])
            if "error" in r:
                print(f"| {d} | {n} | | | error: {r['error']} | | | |")
                continue
            print(f"| {d} | {n} | {r['phi']:.3f} | {r['Z']:.2f} | {r['rate']:.3g} | {r['cpu_rate']:.3g} "
                  f"| {r['neighbours']:.1f} | {r['peak_mb']:.0f} |", flush=True)


def section_poly(quick: bool, repeats: int) -> None:
    print(f"\n## Wide size distribution: 3D, N = 1e4, phi = 0.5, NVE collisions per second; "
          f"uniform-in-volume radii over omega = 10 against monodisperse, {repeats} interleaved pairs "
          "(mono, UV, mono, UV, ...; 3 timed windows each) so machine drift cancels in each ratio")
    print("| pair | radii | grid levels | Z | coll/s (wall) | coll/s (CPU) | neighbours | peak MB |")
    print("|---|---|---|---|---|---|---|---|")
    ratios = []
    for k in range(repeats):
        pair = {}
        for omega in (1.0, 10.0):
            r = pair[omega] = _run(["poly", 10000, 3, omega])
            label = "monodisperse" if omega == 1.0 else f"UV omega = {omega:g}"
            if "error" in r:
                print(f"| {k + 1} | {label} | error: {r['error']} | | | | | |")
                continue
            print(f"| {k + 1} | {label} | {r['levels']} | {r['Z']:.2f} | {r['rate']:.3g} "
                  f"| {r['cpu_rate']:.3g} | {r['neighbours']:.1f} | {r['peak_mb']:.0f} |", flush=True)
        if all("error" not in r for r in pair.values()):
            ratios.append(pair[1.0]["cpu_rate"] / pair[10.0]["cpu_rate"])
    if ratios:
        print(f"CPU-rate ratio monodisperse / UV omega = 10: median {statistics.median(ratios):.2f} "
              f"(pairs: {', '.join(f'{x:.2f}' for x in ratios)})")


def section_jam(quick: bool, repeats: int) -> None:
    print(f"\n## Time to jam: N = 1e4, d = 3, Gamma = 0.02, RSA phi0 = 0.1 -> Z = 1e12 (median of "
          f"{repeats}, compile excluded)")
    runs = [_run(["jam", 10000, 0.02]) for _ in range(repeats)]
    runs = [r for r in runs if "error" not in r] or runs
    if "error" in runs[0]:
        print("error:", runs[0]["error"])
        return
    runs.sort(key=lambda r: r["wall_s"])
    r = runs[len(runs) // 2]
    walls = ", ".join(f"{x['wall_s']:.1f}" for x in runs)
    print(f"wall {r['wall_s']:.1f} s (all: {walls}), "
          f"CPU {r['cpu_s']:.1f} s, phi_J = {r['phi']:.4f}, Z = {r['Z']:.3g}, "
          f"{r['collisions']:.3g} collisions, {r['rate']:.3g} coll/s overall, "
          f"{r['dense_rate']:.3g} coll/s for Z >= 1e3, peak {r['peak_mb']:.0f} MB")


SECTIONS = {"compile": section_compile, "fluid": section_fluid, "poly": section_poly, "jam": section_jam}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small table, one repeat")
    parser.add_argument("--repeats", type=int, help="timed repeats per configuration")
    parser.add_argument("--only", nargs="+", choices=SECTIONS, default=list(SECTIONS),
                        help="run only these sections (default: all)")
    parser.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        kind, *rest = args.worker
        if kind == "rate":
            result = worker_rate(int(rest[0]), int(rest[1]), int(rest[2]))
        elif kind == "poly":
            result = worker_rate(3, int(rest[0]), int(rest[1]), phi=0.5, omega=float(rest[2]))
        elif kind == "jam":
            result = worker_jam(int(rest[0]), float(rest[1]))
        else:
            result = worker_compile(int(rest[0]))
        print(json.dumps(result))
        return

    repeats = args.repeats or (1 if args.quick else 3)
    print(f"hardpack.md benchmark ({'quick' if args.quick else 'full'}), {os.cpu_count()} CPUs, "
          f"load average {os.getloadavg()[0]:.1f}")
    for name, section in SECTIONS.items():
        if name in args.only:
            section(args.quick, repeats)


if __name__ == "__main__":
    main()
