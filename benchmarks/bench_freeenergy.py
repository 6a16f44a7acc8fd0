"""Events per second of BCMD (hardpack.freeenergy) vs the plain hard-sphere engine (hardpack.md).

Same FCC packing (N = 256) and density for both. Plain engine: NVE ``equilibrate`` (collisions /
wall time). BCMD: pair + wall events / wall time of (a) the full melting run of the validation
(phi = 0.545, dmu 1 -> disjoint point 0.1076, theta = 1), (b) its first, most expensive part
(dmu 1 -> 0.5, up to 42 cell neighbours), (c) the full jamming-limit run (delta = 1e-6,
dmu 1e-5 -> 1e-6, theta = 0.5) against the plain engine at that density. Rates are per second
of process CPU time (both codes are single-threaded), which the other jobs of a shared machine
disturb much less than wall time; medians over repeats.
Run: ``python benchmarks/bench_freeenergy.py [repeats]``.
"""

from __future__ import annotations

import statistics
import sys
import time

from hardpack.freeenergy.bcmd import run_bcmd
from hardpack.geometry.lattices import lattice_packing
from hardpack.md import equilibrate


def fcc(phi=None, delta=None):
    p = lattice_packing("fcc", (4, 4, 4))
    if phi is not None:
        return p.replace(radii=p.radii * (phi / p.phi) ** (1 / 3))
    return p.replace(radii=p.radii * (1 - delta))


def bcmd_rate(p, **kw):
    t = time.process_time()
    a = run_bcmd(p, partial=True, **kw).to_dataset().attrs
    return a["n_events"] / (time.process_time() - t)


def plain_rate(p, seed):
    t = time.process_time()
    res = equilibrate(p, seed=seed, n_collisions=2_000_000, n_equilibration=0)
    return res.collisions / (time.process_time() - t)


def main(repeats: int = 3) -> None:
    melt, jam = fcc(phi=0.545), fcc(delta=1e-6)
    for p in (melt, jam):  # compile
        equilibrate(p, seed=0, n_collisions=20_000)
    run_bcmd(melt, dmu_max=1.0, dmu_min=0.9, gamma0=1e-2, seed=0, partial=True)
    cases = {
        "plain engine, phi = 0.545": lambda r: plain_rate(melt, r),
        "BCMD, phi = 0.545, full run dmu 1 -> 0.1076": lambda r: bcmd_rate(
            melt, dmu_max=1.0, gamma0=1e-3, seed=r),
        "BCMD, phi = 0.545, dmu 1 -> 0.5": lambda r: bcmd_rate(
            melt, dmu_max=1.0, dmu_min=0.5, gamma0=1e-3, seed=r),
        "plain engine, delta = 1e-6": lambda r: plain_rate(jam, r),
        "BCMD, delta = 1e-6, full run": lambda r: bcmd_rate(
            jam, dmu_max=1e-5, gamma0=1e-3, theta=0.5, seed=r),
    }
    rates = {name: [] for name in cases}
    for r in range(repeats):
        for name, case in cases.items():
            rates[name].append(case(r))
    for name, vals in rates.items():
        print(f"{name:45s} median {statistics.median(vals):.3g} events/s  "
              f"{[f'{v:.3g}' for v in vals]}", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
