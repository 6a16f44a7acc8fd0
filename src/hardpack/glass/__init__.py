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
- :mod:`hardpack.glass.soc`: compression of single-occupancy-cell (SOC) solids, each disk growing in
  a fixed cell (sec. 13.3.1, Fig. 13.9), and the summary of their jamming densities.
- :mod:`hardpack.glass.segregated`: the micro-segregated labels of sec. 13.5 (level-cut Matérn
  Gaussian random fields), their window entropies s_{n,m} and the labelled start crystal.
- :mod:`hardpack.glass.microsegregated`: growth of the labelled crystal's B disks at constant
  pressure and compression to jamming (sec. 13.5, with :mod:`hardpack.md.deforming`).
"""
