"""The analytic cost model of hierarchical-grid (HGrid) contact detection (Ogarko ch. 2.2) and its Fig. 2.15
study (``hardpack hgrid-cost``).

- :mod:`hardpack.hgrid.cost_model`  analytic cost T/N of an HGrid for power-law radii (ch. 2.2)

The HGrid itself (level assignment, search, RSA) is the neighbour layer, :mod:`hardpack.geometry.neighbours`.
"""
