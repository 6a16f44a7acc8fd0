"""Benchmark of the deforming-cell sphere MD (hardpack.md.deforming): the share of the neighbour
list builds and the pair searches of the cell deformation in a compression, before and after a
change, in one run. Prints a table; never part of the test suite.

    python benchmarks/bench_deforming.py --baseline /path/to/other/checkout/src
    python benchmarks/bench_deforming.py --baseline SRC --only 500x3   # one configuration

Every (configuration, source tree) runs in its own subprocess with PYTHONPATH set to that tree's
src (this checkout's, and the ``--baseline`` one if given), numba compiled by a small run first.
Configuration NxD: N monodisperse spheres in d dimensions from RSA (phi = 0.3 in 3D, 0.15 in 4D),
LS growth rate 0.02 in the deforming cell (shape only, adaptive cell) to the reduced pressure Z
of the row, seed 0. Timed (CPU time, process_time, since the machine may be shared):

- the whole compression, and inside it the event windows (``run_events``, which include the list
  builds) and the pair searches of the deformation and the overlap check (``strain_limit``);
- one complete build of all neighbour lists (every window starts with one) and the rebuild of one
  list (every bounding-sphere exit), standalone (numba loops over the particles) on the final
  packing with bounding radii a + SHELL_START <a>: the exhaustive scan (``list_particle``) or,
  where the tree has it, the cell grid (``list_particle_grid``). Their share of the compression
  is estimated as windows x complete build + exits x one rebuild (the lists of the dense final
  packing: an upper estimate for the earlier, less dense windows).

Both trees must give the same collisions and final phi (same seed; the grid changes no list).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

CONFIGS = {"500x3": (500, 3, 1e3), "2000x3": (2000, 3, 1e2), "500x4": (500, 4, 1e2)}


def worker(n: int, d: int, zmax: float) -> dict:
    import numpy as np

    from hardpack.distributions import monodisperse
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, deforming
    from hardpack.md import _deforming_kernel as dk
    from hardpack.md.deforming import SHELL_START, compress_deforming, shortest_vector

    phi0 = {3: 0.3, 4: 0.15}[d]
    compress_deforming(random_packing(20, d, monodisperse(), phi0, 0), 0.02, 0, StopCriteria(max_pressure=1e2))
    spent = {"run_events": 0.0, "strain_limit": 0.0}

    def timing(name):
        fn = getattr(dk, name)

        def wrapped(*args):
            t0 = time.process_time()
            out = fn(*args)
            spent[name] += time.process_time() - t0
            return out
        return wrapped

    for name in spent:
        setattr(dk, name, timing(name))
    start = random_packing(n, d, monodisperse(), phi0, 0)
    t0 = time.process_time()
    res = compress_deforming(start, 0.02, 0, StopCriteria(max_pressure=zmax))
    total = time.process_time() - t0

    final = res.packing
    H = np.array(final.lattice)
    X = np.array(final.positions)
    a = np.array(final.radii)
    bs = np.empty((n, d + 1))
    bs[:, :d] = X
    bs[:, d] = a + SHELL_START * a.mean()
    Hinv = np.linalg.inv(H)
    lmin = shortest_vector(H)
    M = dk.image_ranges(H, lmin)
    strides = np.cumprod(np.concatenate([[1], 2 * M[:-1] + 1])).astype(np.int64)
    m = int(np.prod(2 * M + 1))
    cfac = np.linalg.norm(Hinv, axis=1)
    cap = 256
    nb, nn = np.zeros((n, cap), dtype=np.int64), np.zeros(n, dtype=np.int64)
    grid = hasattr(dk, "list_particle_grid")
    if grid:
        n_cells, cstr = deforming.cell_grid(H, 2 * float(bs[:, d].max()), n)
        lists = (np.empty(int(np.prod(n_cells)), dtype=np.int64), np.empty(n, dtype=np.int64),
                 np.empty(n, dtype=np.int64), np.empty((n, d), dtype=np.int64), np.empty((n, d)),
                 np.empty(cap, dtype=np.int64))
        args = (bs, H, Hinv, M, strides, nb, nn, m, cfac, lmin, float(bs[:, d].max()), n_cells, cstr) + lists
    else:
        args = (bs, H, Hinv, M, strides, nb, nn, m, cfac, lmin)
    complete, rebuild = _list_loops(grid)
    complete(*args)
    rebuild(*args)
    reps = 3
    t0 = time.process_time()
    for _ in range(reps):
        complete(*args)
    t_complete = (time.process_time() - t0) / reps
    t0 = time.process_time()
    rebuild(*args)
    t_one = (time.process_time() - t0) / n
    windows = int(res.stats["windows"])
    exits = int(np.sum(res.timeseries.exits.values))
    lists = windows * t_complete + exits * t_one
    return {"grid": grid, "total": total, "run_events": spent["run_events"], "strain_limit": spent["strain_limit"],
            "complete_build": t_complete, "one_rebuild": t_one, "windows": windows, "exits": exits,
            "lists_estimate": lists, "collisions": int(res.stats["collisions"]), "phi": float(res.stats["phi"])}


def _list_loops(grid: bool):
    """Numba loops over all particles: the complete build of a window's lists, and every list's
    rebuild (each from empty lists, as after an exit), with the grid or the scan."""
    from numba import njit

    from hardpack.md import _deforming_kernel as dk

    if grid:
        @njit
        def complete(bs, H, Hinv, M, strides, nb, nn, m, cfac, lmin, rmax, n_cells, cstr, head, nxt, cell_of, wrap,
                     sw, ent):
            nn[:] = 0
            dk.link_cells(bs, Hinv, n_cells, cstr, head, nxt, cell_of, wrap, sw)
            for i in range(bs.shape[0]):
                dk.list_particle_grid(i, i, bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin, rmax, n_cells, cstr,
                                      head, nxt, wrap, sw, ent)

        @njit
        def rebuild(bs, H, Hinv, M, strides, nb, nn, m, cfac, lmin, rmax, n_cells, cstr, head, nxt, cell_of, wrap,
                    sw, ent):
            nn[:] = 0
            for i in range(bs.shape[0]):
                dk.list_particle_grid(i, bs.shape[0], bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin, rmax,
                                      n_cells, cstr, head, nxt, wrap, sw, ent)
                for e in range(nn[i]):
                    nn[nb[i, e] // m] = 0
                nn[i] = 0
    else:
        @njit
        def complete(bs, H, Hinv, M, strides, nb, nn, m, cfac, lmin):
            nn[:] = 0
            for i in range(bs.shape[0]):
                dk.list_particle(i, i, bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin)

        @njit
        def rebuild(bs, H, Hinv, M, strides, nb, nn, m, cfac, lmin):
            nn[:] = 0
            for i in range(bs.shape[0]):
                dk.list_particle(i, bs.shape[0], bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin)
                for e in range(nn[i]):
                    nn[nb[i, e] // m] = 0
                nn[i] = 0
    return complete, rebuild


def run(src: str, key: str) -> dict:
    env = dict(os.environ, PYTHONPATH=src)
    out = subprocess.run([sys.executable, __file__, "--worker", key], env=env, capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--baseline", help="src directory of the tree to compare with")
    parser.add_argument("--only", choices=sorted(CONFIGS))
    parser.add_argument("--worker")
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(worker(*CONFIGS[args.worker])))
        return
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
    trees = ([("baseline", args.baseline)] if args.baseline else []) + [("this", here)]
    head = (f"{'config':8s} {'tree':8s} {'cpu_s':>8s} {'events':>7s} {'strain':>7s} {'lists~':>7s} {'build_ms':>9s} "
            f"{'one_us':>7s} {'windows':>7s} {'exits':>8s} {'collisions':>10s} {'phi':>8s}")
    print(head, flush=True)
    for key in ([args.only] if args.only else CONFIGS):
        rows = {}
        for name, src in trees:
            r = rows[name] = run(src, key)
            print(f"{key:8s} {name:8s} {r['total']:8.1f} {r['run_events'] / r['total']:7.1%} "
                  f"{r['strain_limit'] / r['total']:7.1%} {r['lists_estimate'] / r['total']:7.1%} "
                  f"{1e3 * r['complete_build']:9.2f} {1e6 * r['one_rebuild']:7.1f} {r['windows']:7d} {r['exits']:8d} "
                  f"{r['collisions']:10d} {r['phi']:8.5f}", flush=True)
        if len(rows) == 2:
            b, t = rows["baseline"], rows["this"]
            same = b["collisions"] == t["collisions"] and b["phi"] == t["phi"]
            print(f"{key:8s} ratios baseline/this: compression {b['total'] / t['total']:.2f}, run_events "
                  f"{b['run_events'] / t['run_events']:.2f}, strain_limit {b['strain_limit'] / t['strain_limit']:.2f}, "
                  f"complete build {b['complete_build'] / t['complete_build']:.1f}, one rebuild "
                  f"{b['one_rebuild'] / t['one_rebuild']:.1f}; same trajectory: {same}", flush=True)


if __name__ == "__main__":
    main()
