"""Snakemake script: the fully phase-separated crystal of the mixture (after Donev 2006, Fig. 13.4)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_separated
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_glass_separated(load_dataset(snakemake.input[0]))
save(fig, snakemake.output.pdf, snakemake.output.png)
