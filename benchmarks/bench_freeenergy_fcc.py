"""FCC validation sweeps of BCMD against the published numbers (Donev 2006,
dissertation sec. 6.4.1): the excess free energy at phi = 0.545 (5.91916) and the jamming-limit constant
f_J - f_c^J (2.160), over N and gamma0, one frozen particle, lattice-centred cells.

    python benchmarks/bench_freeenergy_fcc.py --reps 3 4 5 --gamma0 1e-3 3e-3 --seeds 1 2
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hardpack.freeenergy.bcmd import run_bcmd
from hardpack.geometry.lattices import lattice_packing

PUBLISHED = {"melting": 5.91916, "jamming": 2.160}


def fcc_case(case: str, reps: int):
    p = lattice_packing("fcc", (reps,) * 3)
    if case == "melting":  # phi = 0.545, dmu_max = 1, theta = 1 (Donev 2006, sec. 6.4.1)
        p = p.replace(radii=p.radii * (0.545 / p.phi) ** (1 / 3))
        return p, {"dmu_max": 1.0, "theta": 1.0}
    delta = 1e-6  # delta = 1e-6, dmu_max = 10 delta, theta = 0.5 (Donev 2006, sec. 6.4.1)
    return p.replace(radii=p.radii * (1 - delta)), {"dmu_max": 10 * delta, "theta": 0.5}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--case", choices=sorted(PUBLISHED), nargs="+", default=sorted(PUBLISHED)
    )
    ap.add_argument("--reps", type=int, nargs="+", default=[3, 4])
    ap.add_argument("--gamma0", type=float, nargs="+", default=[1e-3])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1])
    args = ap.parse_args()
    for case in args.case:
        for reps in args.reps:
            p, kw = fcc_case(case, reps)
            n = p.n_particles
            for g in args.gamma0:
                for seed in args.seeds:
                    t = time.perf_counter()
                    res = run_bcmd(p, gamma0=g, seed=seed, **kw)
                    value = res.excess if case == "melting" else res.delta_f
                    el = time.perf_counter() - t
                    print(
                        f"{case:8s} N={n:5d} gamma0={g:.0e} seed={seed} value={value:.4f} "
                        f"published={PUBLISHED[case]} diff={value - PUBLISHED[case]:+.4f} "
                        f"3lnN/N={3 * np.log(n) / n:.4f} events={res.to_dataset().attrs['n_events']} "
                        f"time={el:.0f}s",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
