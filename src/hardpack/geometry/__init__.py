"""Geometry: the packing model (particle shapes, boundaries), d-ball volumes, the neighbour layer
(:mod:`.neighbours`) and crystal lattices.

The neighbour layer is imported on first use (``PairList``, ``pairs_within``): it compiles numba
kernels, and a job that only reads or writes packings (``hardpack combine``, the figures) need not
import numba at all (0.45 s of each such job's start-up, measured).
"""

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

#: names of the neighbour layer, imported from :mod:`hardpack.geometry.neighbours` on first access
_NEIGHBOUR_NAMES = ("PairList", "pairs_within")


def __getattr__(name: str):
    if name in _NEIGHBOUR_NAMES:
        from hardpack.geometry import neighbours

        return getattr(neighbours, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
