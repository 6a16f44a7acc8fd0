"""Snakemake script: Table II figure from the SLP densest-packing summary."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.slp import plot_densest
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
save(plot_densest(load_dataset(snakemake.input[0], kind="ensemble")), snakemake.output.pdf, snakemake.output.png)
