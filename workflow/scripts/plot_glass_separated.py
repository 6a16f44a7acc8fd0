"""Snakemake script: the fully phase-separated crystal of the mixture and its decompressions (after
Donev 2006, Figs. 13.4-13.5)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_separated
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_glass_separated(load_dataset(snakemake.input.freezing),
                           [load_dataset(path) for path in snakemake.input.decompressions])
save(fig, snakemake.output.pdf, snakemake.output.png)
