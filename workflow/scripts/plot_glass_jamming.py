"""Snakemake script: jamming densities of the mixture vs growth rate, before and after relaxation."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_jamming
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_glass_jamming(load_dataset(snakemake.input.eos), load_dataset(snakemake.input.relaxed))
save(fig, snakemake.output.pdf, snakemake.output.png)
