"""Geometry: the packing model (particle shapes, boundaries), d-ball volumes, the neighbour layer
(:mod:`.neighbours`) and crystal lattices."""

from hardpack.geometry.balls import ball_volume, unit_ball_volume
from hardpack.geometry.boundaries import (
    ContainmentReport,
    HardWalls,
    Periodic,
    SphericalContainer,
)
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.neighbours import PairList, pairs_within
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, OverlapReport, Packing
from hardpack.geometry.shapes import Ellipsoids, Spheres

__all__ = [
    "Packing", "OverlapReport", "DEFAULT_OVERLAP_TOL", "PairList", "pairs_within",
    "Spheres", "Ellipsoids", "Periodic", "HardWalls", "SphericalContainer", "ContainmentReport",
    "ball_volume", "unit_ball_volume", "lattice_packing",
]
