"""Snakemake script: pressure relaxation of the mixture's glasses at fixed phi (after Donev 2006, Fig. 13.7)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_relaxation
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_glass_relaxation([load_dataset(path) for path in snakemake.input])
save(fig, snakemake.output.pdf, snakemake.output.png)
