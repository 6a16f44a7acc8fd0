"""Snakemake script: s_c vs phi_J of the micro-segregated packings (after Donev 2006, Fig. 13.16)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_microsegregated
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_microsegregated(load_dataset(snakemake.input[0], kind="microsegregated_summary"))
save(fig, snakemake.output.pdf, snakemake.output.png)
