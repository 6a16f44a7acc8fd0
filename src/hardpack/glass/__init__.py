"""Configurational entropy of binary hard-disk glasses (Donev 2006, ch. 13; Donev, Stillinger &
Torquato 2006).

- :mod:`hardpack.glass.thermo`: excess free energy from the EOS (integral from the ideal gas),
  second-virial limit, mixing entropy, s_c - s_mix = Delta f_g - Delta f_L (Eq. 13.5).
- :mod:`hardpack.glass.fits`: phi~_J(phi), the liquid-extension cubic (Eq. 13.3) and the glassy
  branch (Eq. 13.4) by weighted least squares with coefficient errors.
- :mod:`hardpack.glass.freezing`: freezing by chemical-potential matching against the pure
  large-disk crystal (Eq. 13.2).
- :mod:`hardpack.glass.study`: the triangular start crystal, binned EOS of compressions and the
  summaries of the pipeline.

Not implemented: the micro-segregated packings of sec. 13.5 (they need a constant-pressure,
deforming-cell event-driven MD that hardpack does not have).
"""
