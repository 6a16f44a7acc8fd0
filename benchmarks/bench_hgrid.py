"""Benchmark: hierarchical-grid (HGrid) neighbour search vs the single-level grid (linked cells).

    python benchmarks/bench_hgrid.py            # UV omega = 50, N = 125001, phi = 0.6 (ch. 2.1 setup)
    python benchmarks/bench_hgrid.py --quick    # UV omega = 20, N = 30000, phi = 0.5

Ogarko (dissertation, Sec. 2.1.4) reports the optimal HGrid ~220x faster than linked cells for UV
radii (f ~ a^-3) with omega = 50, N = 125001 at phi = 0.62 (DEM, contact detection per time step).

Configuration: N radii by systematic sampling of UV(omega), placed by largest-first random sequential
addition directly at the target phi in a periodic cube (hardpack.geometry.neighbours.rsa; RSA of such wide
distributions reaches phi = 0.6, no compression needed). It has RSA's pair correlations, not those of a
jammed packing; the search cost depends mainly on the radii and phi.

Timed: one complete search of the neighbour layer with a precomputed level assignment,
:func:`hardpack.geometry.neighbours.build_grid` and :func:`~hardpack.geometry.neighbours.grid_pairs` (sort
by cell, fill the cell lists, Top-Down search, sort the pair list), for skin = 0 (contact
detection; RSA leaves no contacts) and skin = 0.1 <a> (a neighbour list). The HGrid uses the optimal
number of levels (min L (m + K), K = 0.3, Eq. 2.7); the single-level grid is the same code with L = 1.
CPU time (process_time) and wall time are medians over repeats; the machine may be shared. Both methods
must return identical pair lists. Also printed: distance tests and cell visits per particle and the
cost model's T/N for the same radii (Eq. 2.35, K = 0.2, which assumes no excluded volume).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from hardpack.distributions import uniform_volume
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours import build_grid, grid_pairs, optimal_levels, random_sequential_addition
from hardpack.hgrid.cost_model import PowerLawSystem, best_levels


def timed(fn, repeats):
    cpu, wall, out = [], [], None
    for _ in range(repeats):
        c0, w0 = time.process_time(), time.perf_counter()
        out = fn()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    return statistics.median(cpu), statistics.median(wall), out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=5, help="repeats of the HGrid search (default 5)")
    ap.add_argument("--single-repeats", type=int, default=3, help="repeats of the single-level search")
    args = ap.parse_args(argv)
    omega, n, phi = (20.0, 30_000, 0.5) if args.quick else (50.0, 125_001, 0.6)

    radii = uniform_volume(omega).sample(n, np.random.default_rng(1))
    box = np.full(3, (ball_volume(radii, 3).sum() / phi) ** (1 / 3))
    c0 = time.process_time()
    x = random_sequential_addition(radii, box, seed=1)
    print(f"UV omega = {omega:g}, N = {n}, phi = {phi}: HGrid RSA in {time.process_time() - c0:.1f} s CPU "
          f"(box side {box[0]:.1f} <a>, largest diameter {2 * radii.max():.1f} <a>)")

    model = PowerLawSystem(-3.0, omega, phi, 3)
    L_model, t_model, _ = best_levels(model, "constant-m", L_max=30)
    print(f"cost model T/N (K = 0.2): linked cells {model.linked_cell_cost():.0f}, constant-m HGrid "
          f"{t_model:.2f} at L = {L_model} -> predicted work ratio {model.linked_cell_cost() / t_model:.0f}")

    rows = []
    frac, lattice = x / box, np.diag(box)

    def search(reach, levels):
        return grid_pairs(build_grid(frac, lattice, reach, levels=levels))

    for skin in (0.0, 0.1):
        reach = radii + 0.5 * skin
        c0 = time.process_time()
        levels = optimal_levels(reach, float(np.prod(box)), 3)
        t_plan = time.process_time() - c0
        search(reach, levels)  # compile outside the timing
        hg = timed(lambda: search(reach, levels), args.repeats)
        lc = timed(lambda: search(reach, 1), args.single_repeats)
        same = all(np.array_equal(getattr(hg[2], k), getattr(lc[2], k)) for k in ("i", "j", "shift"))
        rows.append((skin, levels, t_plan, hg, lc, same))

    print(f"\n{'skin':>5} {'method':>14} {'L':>3} {'pairs':>9} {'tests/N':>9} {'visits/N':>9} "
          f"{'CPU s':>9} {'wall s':>9} {'speed-up (CPU)':>15}")
    for skin, levels, t_plan, hg, lc, same in rows:
        for name, res, L in (("HGrid (ONL)", hg, levels.n_levels), ("single level", lc, 1)):
            r = res[2]
            ratio = lc[0] / hg[0] if name.startswith("HGrid") else 1.0
            print(f"{skin:5.2f} {name:>14} {L:3d} {len(r):9d} {r.distance_tests / n:9.1f} {r.cell_visits / n:9.1f} "
                  f"{res[0]:9.4f} {res[1]:9.4f} {ratio:15.0f}")
        print(f"      level plan (once per radius set): {t_plan:.2f} s CPU; identical pair lists: {same}")
        if not same:
            raise SystemExit("HGrid and single-level pair lists differ")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
