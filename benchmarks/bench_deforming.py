"""Benchmark of the deforming-cell MD of spheres and ellipsoids (hardpack.md.deforming): the share of
the neighbour list builds and the pair searches of the cell deformation in a compression, before
and after a change, in one run. Prints a table; never part of the test suite.

    python benchmarks/bench_deforming.py --baseline /path/to/other/checkout/src
    python benchmarks/bench_deforming.py --baseline SRC --only 500x3   # one configuration
    python benchmarks/bench_deforming.py --baseline SRC --only ell500x3 --repeat 3   # alternating runs

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

Configuration ellNxD (:data:`ELLIPSOID_CONFIGS`): N prolate spheroids 1 : 1 : sqrt 3 in d = 3 from
RSA at phi = 0.3, LS growth rate 0.05 in the deforming cell (shape only, adaptive cell) for a
fixed number of collisions, seed 0. Timed: the whole run, the event windows
(``_ellipsoid_deforming_kernel.run_events``, with the list builds) and the pair searches of the
deformation and the overlap check (``near_pairs``), and standalone on the final packing one
complete build of the lists with the first predictions (``run_events`` stopped at t = 0) and one
``near_pairs`` at scale 1 (with the tree's grid set-up). Without ``--only`` the sphere
configurations and ell500x3 run.

``--repeat K`` runs every configuration K times, the trees alternating, and reports the ratios
of the medians. Both trees must give the same collisions and final phi (same seed; the grid
changes no list), for ellipsoids also the same final positions and orientations (digest).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

CONFIGS = {"500x3": (500, 3, 1e3), "2000x3": (2000, 3, 1e2), "500x4": (500, 4, 1e2)}
#: ellipsoid configurations: (N, d, collisions)
ELLIPSOID_CONFIGS = {"ell500x3": (500, 3, 100_000), "ell2000x3": (2000, 3, 200_000)}


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


def ellipsoid_worker(n: int, d: int, collisions: int) -> dict:
    import hashlib
    import inspect

    import numpy as np

    from hardpack.initial import random_ellipsoid_packing
    from hardpack.md import StopCriteria, maxwell_boltzmann
    from hardpack.md import _deforming_kernel as dk
    from hardpack.md import _ellipsoid_deforming_kernel as edk
    from hardpack.md import _ellipsoid_kernel as ek
    from hardpack.md._kernel import A_KE
    from hardpack.md.deforming import EllipsoidDeformingSimulation, cell_grid, compress_deforming
    from hardpack.md.ellipsoid import random_angular_velocities
    from hardpack.md.ellipsoid_engine import moments_of_inertia

    prolate = np.array([np.sqrt(3.0), 1.0, 1.0])
    compress_deforming(random_ellipsoid_packing(20, prolate, 0.3, seed=0), 0.05, 0,
                       StopCriteria(max_pressure=None, max_collisions=2000))
    spent = {"run_events": 0.0, "near_pairs": 0.0}

    def timing(name):
        fn = getattr(edk, name)

        def wrapped(*args):
            t0 = time.process_time()
            out = fn(*args)
            spent[name] += time.process_time() - t0
            return out
        wrapped.py_func = fn.py_func
        return wrapped

    for name in spent:
        setattr(edk, name, timing(name))
    start = random_ellipsoid_packing(n, prolate, 0.3, seed=0)
    t0 = time.process_time()
    res = compress_deforming(start, 0.05, 0, StopCriteria(max_pressure=None, max_collisions=collisions))
    total = time.process_time() - t0

    final = res.packing
    grid = "n_cells" in inspect.signature(edk.run_events.py_func).parameters
    sim = EllipsoidDeformingSimulation(
        final, maxwell_boltzmann(n, d, 1), random_angular_velocities(n, d, moments_of_inertia(final.shape.semiaxes), 2),
        0.0)
    H, Hinv = sim.H, np.linalg.inv(sim.H)
    cr = ek.columns(d)[2]
    rb = sim.P[:, cr]
    skin = np.full(n, 0.1 * float(rb.mean()))
    reach = 2.0 * float(rb.max() + skin[0]) * 1.1
    M = dk.image_ranges(H, reach)
    img, cbits = edk.padded_image_table(H, M)
    n_cells, cstr = cell_grid(H, 2.0 * float(rb.max() + skin[0]), n)
    cap = 64
    p0 = sim.P.copy()

    def build():
        sim.P[:] = p0
        nb = np.zeros((n, cap), dtype=np.int64)
        acc = np.zeros(edk.N_ACC)
        acc[A_KE] = 1.0
        args = [sim.P, H, Hinv, M, img, cbits, np.linalg.norm(Hinv, axis=1), reach] + (
            [n_cells, cstr] if grid else []) + [
            0.0, sim.eps_f, skin, sim.bs, nb, sim.nn, sim.mark, sim.cnt, sim.ep, sim.ec, sim.hkey, sim.heap, sim.hpos,
            np.empty(cap), np.empty(cap), np.empty(cap, dtype=np.int8), np.empty((cap, ek.PAIR_STATE)),
            np.zeros((d, d)), np.zeros((d, d)), acc, np.zeros(edk.N_COUNTERS, dtype=np.int64), 10**9, 0.0]
        assert edk.run_events(*args) == dk.DeformingStatus.DONE_TIME

    def pairs():
        args = (sim.P, H, Hinv, 1.0) + (cell_grid(H, 2.0 * float(rb.max()), n) if grid else ())
        return edk.near_pairs(*args)

    out = {}
    for name, fn in (("complete_build", build), ("near_pairs_one", pairs)):
        fn()
        reps = 5
        t0 = time.process_time()
        for _ in range(reps):
            fn()
        out[name] = (time.process_time() - t0) / reps
    digest = hashlib.md5(np.ascontiguousarray(final.positions).tobytes()
                         + np.ascontiguousarray(final.shape.orientations).tobytes()
                         + np.ascontiguousarray(final.lattice).tobytes()).hexdigest()
    return {"grid": grid, "total": total, "run_events": spent["run_events"], "near_pairs": spent["near_pairs"],
            "windows": int(res.stats["windows"]), "exits": int(np.sum(res.timeseries.exits.values)),
            "collisions": int(res.stats["collisions"]), "phi": float(res.stats["phi"]), "digest": digest, **out}


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


def _median(rows, key):
    vals = sorted(r[key] for r in rows)
    m = len(vals)
    return vals[m // 2] if m % 2 else 0.5 * (vals[m // 2 - 1] + vals[m // 2])


def _sphere_row(key, name, r):
    return (f"{key:8s} {name:8s} {r['total']:8.1f} {r['run_events'] / r['total']:7.1%} "
            f"{r['strain_limit'] / r['total']:7.1%} {r['lists_estimate'] / r['total']:7.1%} "
            f"{1e3 * r['complete_build']:9.2f} {1e6 * r['one_rebuild']:7.1f} {r['windows']:7d} {r['exits']:8d} "
            f"{r['collisions']:10d} {r['phi']:8.5f}")


def _ellipsoid_row(key, name, r):
    return (f"{key:9s} {name:8s} {r['total']:8.2f} {r['run_events']:8.2f} {r['near_pairs']:8.3f} "
            f"{1e3 * r['complete_build']:9.2f} {1e3 * r['near_pairs_one']:8.3f} {r['windows']:7d} {r['exits']:8d} "
            f"{r['collisions']:10d} {r['phi']:8.5f} {r['digest'][:8]} load={os.getloadavg()[0]:.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--baseline", help="src directory of the tree to compare with")
    parser.add_argument("--only", choices=sorted(CONFIGS) + sorted(ELLIPSOID_CONFIGS))
    parser.add_argument("--repeat", type=int, default=1, help="runs per tree and configuration, alternating")
    parser.add_argument("--worker")
    args = parser.parse_args()
    if args.worker:
        if args.worker in ELLIPSOID_CONFIGS:
            print(json.dumps(ellipsoid_worker(*ELLIPSOID_CONFIGS[args.worker])))
        else:
            print(json.dumps(worker(*CONFIGS[args.worker])))
        return
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
    trees = ([("baseline", args.baseline)] if args.baseline else []) + [("this", here)]
    keys = [args.only] if args.only else list(CONFIGS) + ["ell500x3"]
    for key in keys:
        ellipsoids = key in ELLIPSOID_CONFIGS
        if ellipsoids:
            print(f"{'config':9s} {'tree':8s} {'cpu_s':>8s} {'events':>8s} {'pairs':>8s} {'build_ms':>9s} "
                  f"{'pairs_ms':>8s} {'windows':>7s} {'exits':>8s} {'collisions':>10s} {'phi':>8s} digest", flush=True)
        else:
            print(f"{'config':8s} {'tree':8s} {'cpu_s':>8s} {'events':>7s} {'strain':>7s} {'lists~':>7s} "
                  f"{'build_ms':>9s} {'one_us':>7s} {'windows':>7s} {'exits':>8s} {'collisions':>10s} {'phi':>8s}",
                  flush=True)
        rows = {name: [] for name, _ in trees}
        for _ in range(args.repeat):
            for name, src in trees:
                r = run(src, key)
                rows[name].append(r)
                print((_ellipsoid_row if ellipsoids else _sphere_row)(key, name, r), flush=True)
        if len(rows) == 2:
            b, t = rows["baseline"], rows["this"]
            same = len({(r["collisions"], r["phi"], r.get("digest")) for r in b + t}) == 1

            def ratio(k):
                return _median(b, k) / _median(t, k)
            if ellipsoids:
                print(f"{key:9s} ratios baseline/this (medians of {args.repeat}): run {ratio('total'):.2f}, "
                      f"run_events {ratio('run_events'):.2f}, near_pairs {ratio('near_pairs'):.1f}, complete build "
                      f"{ratio('complete_build'):.1f}, one near_pairs {ratio('near_pairs_one'):.1f}; "
                      f"same trajectory: {same}", flush=True)
            else:
                print(f"{key:8s} ratios baseline/this (medians of {args.repeat}): compression {ratio('total'):.2f}, "
                      f"run_events {ratio('run_events'):.2f}, strain_limit {ratio('strain_limit'):.2f}, complete "
                      f"build {ratio('complete_build'):.1f}, one rebuild {ratio('one_rebuild'):.1f}; "
                      f"same trajectory: {same}", flush=True)


if __name__ == "__main__":
    main()
