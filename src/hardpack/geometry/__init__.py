"""Geometry: the packing model (particle shapes, boundaries), d-ball volumes, the neighbour layer
(:mod:`.neighbours`) and crystal lattices.

The neighbour layer is imported on first use (``PairList``, ``pairs_within``; :mod:`hardpack._lazy`):
it loads numba kernels, which a job that only reads datasets (``hardpack combine``, most figures)
never calls (0.45 s of each such job's start-up, measured).
"""

from hardpack._lazy import lazy_exports
from hardpack.geometry.balls import ball_volume, unit_ball_volume
from hardpack.geometry.boundaries import (
    ContainmentReport,
    HardWalls,
    Periodic,
    SphericalContainer,
)
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, OverlapReport, Packing
from hardpack.geometry.shapes import Ellipsoids, Spheres

__all__ = [
    "Packing", "OverlapReport", "DEFAULT_OVERLAP_TOL", "PairList", "pairs_within",
    "Spheres", "Ellipsoids", "Periodic", "HardWalls", "SphericalContainer", "ContainmentReport",
    "ball_volume", "unit_ball_volume", "lattice_packing",
]

__getattr__, __dir__ = lazy_exports(__name__, {"neighbours": ("PairList", "pairs_within")})
