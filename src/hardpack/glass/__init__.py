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

- :mod:`hardpack.glass.segregated`: the micro-segregated labels of sec. 13.5 (level-cut Matérn
  Gaussian random fields), their window entropies s_{n,m} and the labelled start crystal.

Not implemented: growing the B disks of the labelled crystal at constant pressure and jamming the
micro-segregated packings (sec. 13.5; needs the deforming-cell MD of :mod:`hardpack.md.deforming`).
"""
