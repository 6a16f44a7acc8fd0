"""Snakemake script: FCC free energy vs density (BCMD, EOS integration, cell limit)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.freeenergy import plot_fcc_density
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_fcc_density(load_dataset(snakemake.input.bcmd), load_dataset(snakemake.input.eos))
save(fig, snakemake.output.pdf, snakemake.output.png)
