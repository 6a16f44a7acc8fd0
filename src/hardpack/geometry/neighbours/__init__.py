"""The neighbour layer: every neighbour search of hardpack goes through here.

- :mod:`.levels`  hierarchical levels by Ogarko's rules (dissertation, Sec. 2.1.2-2.1.3): insertion rule
                  Eq. 2.3, equal particles per cell Eqs. 2.6-2.8, optimal number of levels from Eq. 2.7;
- :mod:`.grid`    the hierarchical cell grid over the fractional coordinates of a cell of any shape (all images
                  along its periodic axes, self-images included) and its numba kernels: the pair search (Top-Down,
                  Sec. 2.1.2), pair-distance histograms and window counts;
- :mod:`.pairs`   :class:`PairList`, the one pair-list type, and :func:`pairs_within`, which searches what
                  the packing model says: the shape's bounding radii, images along the boundary's periodic
                  axes only (none across hard walls or in a spherical container);
- :mod:`.rsa`     random sequential addition of polydisperse spheres on the grid.

Users: the MD engine (levels and cells of its bounding-sphere grid), structure (g2, the number variance
of S(k), order metrics, triangulation cutoffs and through them channels), jamming (contact networks), SLP
(influence sphere), initial configurations (RSA), free energies and the overlap check of
:class:`hardpack.geometry.Packing`.
"""

from hardpack.geometry.neighbours.grid import Grid, build_grid, cell_counts
from hardpack.geometry.neighbours.levels import (
    LevelAssignment,
    assign_levels,
    assign_with_threshold,
    choose_levels,
    geometric_levels,
    insertion_levels,
    optimal_levels,
)
from hardpack.geometry.neighbours.pairs import GridPairs, PairList, grid_pairs, pairs_within, wrapped_positions
from hardpack.geometry.neighbours.rsa import random_sequential_addition

__all__ = [
    "PairList", "pairs_within", "wrapped_positions", "Grid", "build_grid", "cell_counts", "GridPairs",
    "grid_pairs", "LevelAssignment", "assign_levels", "assign_with_threshold", "choose_levels",
    "geometric_levels", "insertion_levels", "optimal_levels", "random_sequential_addition",
]
