"""Snakemake script: a rendered jammed packing of M&M-shaped spheroids."""

import logging

from hardpack.io import load_packing
from hardpack.plots.ellipsoids import plot_snapshot
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
save(plot_snapshot(load_packing(snakemake.input[0])), snakemake.output.pdf, snakemake.output.png)
