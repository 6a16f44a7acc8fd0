"""Figures: a shared style (:mod:`hardpack.plots.style`) and one module per study."""
