"""Structure analysis of packings: g2 and Z(l), S(k) and number variance, order metrics,
regular (weighted Delaunay) triangulation and Ogarko's channel analysis.

Every result is an xarray Dataset (write it with :func:`hardpack.io.write_dataset`).
"""

from hardpack._lazy import lazy_exports

#: the public names and their modules, imported on first access (:mod:`hardpack._lazy`)
_EXPORTS = {
    "analysis": ("analyse",),
    "channels": ("apollonius_radius", "channel_histogram", "channel_radii"),
    "containers": ("ball_intersection_volume", "ellipsoid_radial_density_profile", "extrapolate_bulk_density",
                   "radial_density_profile", "window_fluctuations"),
    "order": ("bond_harmonics", "coordination_defects", "crystallinity", "local_qlm", "order_map", "psi6",
              "steinhardt", "translational_order"),
    "pair": ("PowerLawFit", "cumulative_coordination", "fit_coordination_power_law", "fit_power_law",
             "pair_correlation"),
    "sk": ("extrapolate_s0", "number_variance", "structure_factor", "structure_factor_vectors", "wavevectors"),
    "tessellation": ("NeighbourList", "cutoff_neighbours", "neighbour_list", "regular_neighbours"),
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
__all__ = sorted(name for names in _EXPORTS.values() for name in names)
