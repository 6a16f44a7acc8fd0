"""Snakemake script: jamming densities of the mixture vs growth rate, before and after relaxation."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_jamming
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_jamming(load_dataset(snakemake.input.eos), load_dataset(snakemake.input.relaxed))
save(fig, snakemake.output.pdf, snakemake.output.png)
