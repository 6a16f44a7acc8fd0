"""Snakemake script: free energy of monodisperse disks by EOS integration and by BCMD of the crystal."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_crystal
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_glass_crystal(load_dataset(snakemake.input.eos), load_dataset(snakemake.input.crystal))
save(fig, snakemake.output.pdf, snakemake.output.png)
