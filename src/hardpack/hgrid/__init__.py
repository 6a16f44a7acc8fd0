"""Hierarchical grid (HGrid) for contact detection of polydisperse spheres (Ogarko ch. 2).

- :mod:`hardpack.hgrid.cost_model`  analytic cost T/N of an HGrid for power-law radii (ch. 2.2)
- :mod:`hardpack.hgrid.levels`      "equal particles per cell" level assignment for actual radii (ch. 2.1)
- :mod:`hardpack.hgrid.search`      Top-Down HGrid neighbour search in a periodic box (ch. 2.1)
- :mod:`hardpack.hgrid.rsa`         largest-first random sequential addition with HGrid overlap tests
"""
