"""Sequential linear programming (adaptive shrinking cell) packings, Torquato & Jiao (2010)."""

from hardpack.slp.diluted import DilutedRound, diluted_summary, run_diluted
from hardpack.slp.driver import SLPResult, run_slp
from hardpack.slp.lp import Bounds, solve_step
from hardpack.slp.ordermap import order_map_summary

__all__ = ["Bounds", "DilutedRound", "SLPResult", "diluted_summary", "order_map_summary", "run_diluted",
           "run_slp", "solve_step"]
