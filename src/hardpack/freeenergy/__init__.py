"""Free energies of nearly jammed hard-sphere packings (Donev dissertation ch. 6).

- :mod:`hardpack.freeenergy.simplex`: exact simplex volumes (Eq. 6.5) and the jamming-simplex
  constant f_J of isostatic packings (Eqs. 6.3-6.4).
- :mod:`hardpack.freeenergy.bcmd`: bounding-cell molecular dynamics (sec. 6.3), the free energy
  from the kinetic-energy ratio Delta f = (d_f/2) ln(K/K_0) (Eq. 6.12).
- :mod:`hardpack.freeenergy.billiard`: the same identity for a point billiard in a polytope
  intersected with a shrinking ball (Fig. 6.1; validation of the estimator).
- :mod:`hardpack.freeenergy.isostatic`: BCMD of a rattler-free jammed packing against its exact
  jamming simplex (Table 6.1), frozen particle or frozen centre of mass.
- :mod:`hardpack.freeenergy.crystal`: reference curves of the FCC free energy vs density (EOS
  integration from the published melting value, cell limit with the jamming constant).
- :mod:`hardpack.freeenergy.ladder`: the cheap checks against exact values (disjoint cells,
  a billiard in a simplex).
"""

from hardpack._lazy import lazy_exports

#: the public names and their modules, imported on first access (:mod:`hardpack._lazy`)
_EXPORTS = {
    "bcmd": ("BCMDResult", "run_bcmd"),
    "billiard": ("volume_estimate",),
    "isostatic": ("simplex_reference", "simplex_test"),
    "simplex": ("JammingSimplex", "jamming_simplex", "log_simplex_volume"),
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
__all__ = sorted(name for names in _EXPORTS.values() for name in names)
