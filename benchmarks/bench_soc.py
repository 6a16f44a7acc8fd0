"""Events per second of the SOC compression (hardpack.glass.soc) vs the LS engine (hardpack.md).

Same start for both: binary disks (diameter ratio 1.4, one third large, N given) compressed by
the LS engine at Gamma = 1e-2 from an RSA start at phi = 0.3 to phi = 0.70. From there each code
grows the disks at ``--rate`` to the reduced pressure 1e3: the SOC compression with every disk
in a fixed cell of Delta mu = 1 (pair and wall events), the LS engine without cells (collisions).
Rates are per second of process CPU time (both codes are single-threaded); medians over repeats,
interleaved so that the machine's load changes hit both alike.
Run: ``python benchmarks/bench_soc.py [--n 1024] [--rate 1e-3] [--reps 3]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

from hardpack.distributions import bidisperse
from hardpack.glass.soc import compress_in_cells
from hardpack.initial import random_packing
from hardpack.md.compress import StopCriteria, compress


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1024, help="disks (default 1024)")
    parser.add_argument("--rate", type=float, default=1e-3, help="growth rate from phi = 0.70 (default 1e-3)")
    parser.add_argument("--reps", type=int, default=3, help="interleaved repeats (default 3)")
    args = parser.parse_args()
    start = random_packing(args.n, 2, bidisperse(1.4, 1 / 3), 0.3, seed=1)
    start = compress(start, growth_rate=1e-2, seed=1, stop=StopCriteria(target_phi=0.70, max_pressure=1e6)).packing
    compress_in_cells(start, growth_rate=1e-1, max_pressure=20.0, seed=1)  # compile
    soc, ls = [], []
    for rep in range(args.reps):
        t = time.process_time()
        res = compress_in_cells(start, growth_rate=args.rate, max_pressure=1e3, seed=rep)
        soc.append((res.timeseries.attrs["n_events"] / (time.process_time() - t), res.timeseries.attrs["phi_J_est"]))
        t = time.process_time()
        out = compress(start, growth_rate=args.rate, seed=rep, stop=StopCriteria(max_pressure=1e3))
        ls.append((out.timeseries["collisions"].values[-1] / (time.process_time() - t),
                   float(out.timeseries["phi_J_est"].values[-1])))
    soc_rate = statistics.median(r for r, _ in soc)
    ls_rate = statistics.median(r for r, _ in ls)
    print(f"N = {args.n}, rate {args.rate:g}, phi 0.70 -> Z = 1e3, {args.reps} interleaved repeats (CPU time):")
    print(f"  SOC compression (Delta mu = 1): {soc_rate:.3g} events/s, phi_J {[round(float(p), 5) for _, p in soc]}")
    print(f"  LS engine (no cells):           {ls_rate:.3g} collisions/s, phi_J {[round(p, 5) for _, p in ls]}")
    print(f"  SOC / LS: {soc_rate / ls_rate:.2f}")


if __name__ == "__main__":
    main()
