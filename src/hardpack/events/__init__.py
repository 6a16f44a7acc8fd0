"""Primitives of event-driven dynamics shared by the MD engine (:mod:`hardpack.md`) and the
bounding-cell MD (:mod:`hardpack.freeenergy`): the event heap and the event-time roots."""

from hardpack.events.heap import heap_set
from hardpack.events.roots import contact_root, exit_time, pair_time

__all__ = ["contact_root", "exit_time", "heap_set", "pair_time"]
