"""Snakemake script: phi_J and Z vs aspect ratio of the ellipsoid or ellipse packings."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.ellipsoids import plot_jamming_vs_alpha
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
fig = plot_jamming_vs_alpha(load_dataset(snakemake.input[0]), dim=snakemake.params.dim)
save(fig, snakemake.output.pdf, snakemake.output.png)
