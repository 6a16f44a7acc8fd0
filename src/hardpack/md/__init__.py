"""Event-driven (collision-driven) molecular dynamics of hard spheres in d = 2..6 (any d >= 1 runs).

- :func:`compress`: Lubachevsky-Stillinger growth to a reduced pressure, phi, collision count or
  wall-clock limit, with checkpoint/resume; one dimensionless growth rate Gamma (see
  :mod:`hardpack.md.compress` for its definition and conversions to the seeds' conventions),
  optionally a slow final stage (``final_growth_rate`` from ``switch_pressure`` on) for
  isostatic, collectively jammed packings, and optionally the time-averaged MD contact forces
  of the final windows (``contact_forces``, :mod:`hardpack.md.contacts`).
- :func:`equilibrate`: NVE runs at fixed phi measuring the reduced pressure with error bars.

Engine: one predicted event per particle in a 4-ary heap, lazy invalidation with collision
counters, neighbour lists with immobile bounding spheres (Donev's NNL) rebuilt particle by
particle on a (hierarchical, for wide size distributions) cell grid, all masses 1 and kT = 1
(:mod:`hardpack.md._kernel`, :mod:`hardpack.md.engine`).
"""

from hardpack.md.compress import CompressResult, StopCriteria, compress, default_window
from hardpack.md.equilibrate import EquilibriumResult, equilibrate
from hardpack.md.simulation import OverlapError, maxwell_boltzmann

__all__ = [
    "CompressResult",
    "EquilibriumResult",
    "OverlapError",
    "StopCriteria",
    "compress",
    "default_window",
    "equilibrate",
    "maxwell_boltzmann",
]
