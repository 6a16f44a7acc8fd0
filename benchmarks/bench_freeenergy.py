"""Events per second of BCMD (hardpack.freeenergy) vs the plain hard-sphere engine (hardpack.md).

Same system for both: FCC, N = 256, phi = 0.545. Plain engine: NVE equilibrate (collisions /
wall time). BCMD: a short shrink Delta mu 1 -> 0.5 (pair + wall events / wall time) and a
jamming-limit shrink (delta = 1e-6, Delta mu 1e-5 -> 5e-6). Medians over repeats (the machine
is shared: timings are noisy). Run: ``python benchmarks/bench_freeenergy.py [repeats]``.
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
    t = time.perf_counter()
    res = run_bcmd(p, partial=True, **kw)
    return res.dataset.attrs["n_events"] / (time.perf_counter() - t)


def main(repeats: int = 3) -> None:
    melt = fcc(phi=0.545)
    jam = fcc(delta=1e-6)
    equilibrate(melt, seed=0, n_collisions=20_000)  # compile
    run_bcmd(melt, dmu_max=1.0, dmu_min=0.9, gamma0=1e-2, seed=0, partial=True)  # compile
    plain, cells, jammed = [], [], []
    for r in range(repeats):
        res = equilibrate(melt, seed=r, n_collisions=2_000_000)
        plain.append(res.collisions / res.wall_time)
        cells.append(bcmd_rate(melt, dmu_max=1.0, dmu_min=0.5, gamma0=1e-3, seed=r))
        jammed.append(
            bcmd_rate(jam, dmu_max=1e-5, dmu_min=5e-6, gamma0=1e-3, theta=0.5, seed=r)
        )
    for name, vals in (
        ("plain engine (NVE, hardpack.md)", plain),
        ("BCMD, phi = 0.545, dmu 1 -> 0.5", cells),
        ("BCMD, jamming limit delta = 1e-6", jammed),
    ):
        print(
            f"{name:40s} median {statistics.median(vals):.3g} events/s  {[f'{v:.3g}' for v in vals]}"
        )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
