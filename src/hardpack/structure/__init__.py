"""Structure analysis of packings: g2 and Z(l), S(k) and number variance, order metrics,
regular (weighted Delaunay) triangulation and Ogarko's channel analysis.

Every result is an xarray Dataset (write it with :func:`hardpack.io.write_dataset`).
"""

from hardpack.structure.analysis import analyse
from hardpack.structure.channels import (
    apollonius_radius,
    channel_histogram,
    channel_radii,
)
from hardpack.structure.containers import (
    ball_intersection_volume,
    ellipsoid_radial_density_profile,
    extrapolate_bulk_density,
    radial_density_profile,
    window_fluctuations,
)
from hardpack.structure.order import (
    bond_harmonics,
    coordination_defects,
    crystallinity,
    local_qlm,
    order_map,
    psi6,
    steinhardt,
    translational_order,
)
from hardpack.structure.pair import (
    PowerLawFit,
    cumulative_coordination,
    fit_coordination_power_law,
    fit_power_law,
    pair_correlation,
)
from hardpack.structure.sk import (
    extrapolate_s0,
    number_variance,
    structure_factor,
    structure_factor_vectors,
    wavevectors,
)
from hardpack.structure.tessellation import (
    NeighbourList,
    cutoff_neighbours,
    neighbour_list,
    regular_neighbours,
)

__all__ = [
    "ball_intersection_volume", "ellipsoid_radial_density_profile", "extrapolate_bulk_density",
    "radial_density_profile",
    "window_fluctuations",
    "NeighbourList",
    "PowerLawFit",
    "analyse",
    "apollonius_radius",
    "bond_harmonics",
    "channel_histogram",
    "channel_radii",
    "coordination_defects",
    "crystallinity",
    "cumulative_coordination",
    "cutoff_neighbours",
    "extrapolate_s0",
    "fit_coordination_power_law",
    "fit_power_law",
    "local_qlm",
    "neighbour_list",
    "number_variance",
    "order_map",
    "pair_correlation",
    "psi6",
    "regular_neighbours",
    "steinhardt",
    "structure_factor",
    "structure_factor_vectors",
    "translational_order",
    "wavevectors",
]
