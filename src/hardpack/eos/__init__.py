"""Equations of state, moments of size distributions, equivalent mixtures, and phi_J from Z(phi).

- :mod:`hardpack.eos.moments`  raw/scaled/central moments, O1, O2, polydispersity, kurtosis, D_pq,
  bi- and tridisperse equivalents (2- and 3-node Gauss quadratures; Ogarko Eqs. 3.20-3.21, Tables 3.1-3.4)
- :mod:`hardpack.eos.theory`   CS, CSK, PY, Henderson (2D), BMCSL, SCS, SCSK, BCSK, Z_OL, free volume,
  running phi_J estimate, empirical jamming-density fits (Eqs. 3.15, 3.16, 3.52, 3.55)
- :mod:`hardpack.eos.phij`     phi_J from the free-volume law fitted to the last decades of Z
- :mod:`hardpack.eos.study`    poly / bi / tri systems: jamming runs, fluid Z vs BMCSL, summaries
"""
