"""Snakemake script: the phi-T order map figure (Torquato & Jiao Fig. 6) from its summary."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.slp import plot_order_map
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
save(plot_order_map(load_dataset(snakemake.input[0], kind="slp_order_map")), snakemake.output.pdf, snakemake.output.png)
