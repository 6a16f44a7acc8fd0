"""Snakemake script: phi_J and Z vs aspect ratio of the ellipsoid or ellipse packings."""

from hardpack.io import load_dataset
from hardpack.plots.ellipsoids import plot_jamming_vs_alpha
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_jamming_vs_alpha(load_dataset(snakemake.input[0]), dim=snakemake.params.dim)
save(fig, snakemake.output.pdf, snakemake.output.png)
