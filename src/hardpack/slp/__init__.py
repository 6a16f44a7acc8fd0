"""Sequential linear programming (adaptive shrinking cell) packings, Torquato & Jiao (2010)."""

from hardpack.slp.driver import SLPResult, run_slp
from hardpack.slp.lp import Bounds, solve_step

__all__ = ["Bounds", "SLPResult", "run_slp", "solve_step"]
