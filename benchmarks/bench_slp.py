"""Benchmark of the SLP generator (hardpack.slp) against the LS engine (hardpack.md) on the same
starts. Prints a table; never part of the test suite.

    python benchmarks/bench_slp.py                      # d = 3 N = 64, 125, 250, 500; d = 4, 5 N = 243
    python benchmarks/bench_slp.py --cases 3:64 --repeats 1 --no-ls      # quick look

For every (d, N) and seed, one RSA start at phi0(d) (the LS ensembles' starts: 0.2 in 3D, 0.1 in
4D, 0.05 in 5D, 0.03 in 6D) is jammed by

- SLP with the Table I (MRJ) settings: gamma = 1.5 D, bounds 0.1 / 0.1 / 0.5 D, deforming cell,
  stop when the predicted density gain is below run_slp's default 1e-10 (the paper stops at 1e-8,
  Torquato & Jiao 2010, Sec. V.A; why 1e-10: hardpack.slp.driver);
- LS, two stages: Gamma = 0.02 to reduced pressure 1e3, then Gamma = 1e-4 to 1e12;
- LS, one fast stage: Gamma = 0.02 to 1e12.

Reported per (d, N): medians over seeds of the wall and CPU time to the jammed packing, of phi,
and for SLP of the number of LPs, the LP rows and the wall time per LP. The machine may be shared:
CPU time is the steadier number. Numba compilation of the LS engine is excluded (one small
compression runs first). Each case runs in its own subprocess.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time

PHI0 = {2: 0.3, 3: 0.2, 4: 0.1, 5: 0.05, 6: 0.03}
DEFAULT_CASES = ["3:64", "3:125", "3:250", "3:500", "4:243", "5:243"]


def worker(d: int, n: int, seed: int, ls: bool) -> dict:
    import numpy as np

    from hardpack.distributions import monodisperse
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, compress
    from hardpack.slp import Bounds, run_slp

    start = random_packing(n, d, monodisperse(), PHI0[d], seed)
    out = {"d": d, "N": n, "seed": seed}
    res = run_slp(start, 1.5, Bounds(0.1, 0.1, 0.5), progress_every=0)
    h = res.history
    out["slp"] = {"wall": res.wall_seconds, "cpu": res.cpu_seconds, "phi": res.packing.phi,
                  "n_lp": res.n_steps, "converged": res.converged,
                  "lp_wall_median": float(np.median(h["lp_seconds"].values)),
                  "lp_wall_total": float(h["lp_seconds"].sum()),
                  "rows_median": float(np.median(h["n_constraints"].values))}
    if not ls:
        return out
    compress(random_packing(16, d, monodisperse(), PHI0[d], 0), 0.05, 0,
             StopCriteria(max_pressure=1e3))  # numba compilation outside the timings

    def timed(stages):
        t0, c0 = time.perf_counter(), time.process_time()
        p = start
        for rate, pressure in stages:
            p = compress(p, rate, seed, StopCriteria(max_pressure=pressure)).packing
        return {"wall": time.perf_counter() - t0, "cpu": time.process_time() - c0, "phi": p.phi}

    out["ls_two_stage"] = timed([(0.02, 1e3), (1e-4, 1e12)])
    out["ls_fast"] = timed([(0.02, 1e12)])
    return out


def run_case(d: int, n: int, seeds, ls: bool) -> list[dict]:
    rows = []
    for seed in seeds:
        cmd = [sys.executable, __file__, "--worker", f"{d}:{n}:{seed}:{int(ls)}"]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=True)
        rows.append(json.loads(proc.stdout.strip().splitlines()[-1]))
        print(f"  done d={d} N={n} seed={seed}", file=sys.stderr, flush=True)
    return rows


def _median(rows, engine, key):
    import numpy as np

    values = [r[engine][key] for r in rows if engine in r]
    return float(np.median(values)) if values else float("nan")


def table(results: dict) -> str:
    lines = ["| d | N | engine | phi (median) | wall s | CPU s | LPs | rows/LP | wall s per LP |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for (d, n), rows in results.items():
        for engine in ("slp", "ls_two_stage", "ls_fast"):
            if engine not in rows[0]:
                continue
            extra = ("| - | - | - |" if engine != "slp" else
                     f"| {_median(rows, engine, 'n_lp'):.0f} | {_median(rows, engine, 'rows_median'):.0f} | "
                     f"{_median(rows, engine, 'lp_wall_median'):.3f} |")
            lines.append(f"| {d} | {n} | {engine} | {_median(rows, engine, 'phi'):.4f} | "
                         f"{_median(rows, engine, 'wall'):.1f} | {_median(rows, engine, 'cpu'):.1f} {extra}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", nargs="+", default=DEFAULT_CASES, help="d:N pairs")
    ap.add_argument("--repeats", type=int, default=3, help="seeds per case (medians over them)")
    ap.add_argument("--no-ls", action="store_true", help="SLP only")
    ap.add_argument("--json", help="also write all raw results to this JSON file")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        d, n, seed, ls = (int(v) for v in args.worker.split(":"))
        print(json.dumps(worker(d, n, seed, bool(ls))))
        return
    results = {}
    for case in args.cases:
        d, n = (int(v) for v in case.split(":"))
        results[(d, n)] = run_case(d, n, range(1, args.repeats + 1), not args.no_ls)
    print(table(results))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump([r for rows in results.values() for r in rows], fh, indent=1)


if __name__ == "__main__":
    main()
