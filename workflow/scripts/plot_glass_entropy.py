"""Snakemake script: excess free energies of liquid and SOC glasses, s_c - s_mix vs phi."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_entropy
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_glass_entropy(load_dataset(snakemake.input.binary), load_dataset(snakemake.input.mono))
save(fig, snakemake.output.pdf, snakemake.output.png)
