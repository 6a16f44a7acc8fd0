"""Sequential linear programming (adaptive shrinking cell) packings, Torquato & Jiao (2010)."""

from hardpack._lazy import lazy_exports

#: the public names and their modules, imported on first access (:mod:`hardpack._lazy`)
_EXPORTS = {
    "diluted": ("DilutedRound", "diluted_summary", "run_diluted"),
    "driver": ("SLPResult", "run_slp"),
    "lp": ("Bounds", "solve_step"),
    "ordermap": ("order_map_summary",),
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
__all__ = sorted(name for names in _EXPORTS.values() for name in names)
