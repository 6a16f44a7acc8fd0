"""Snakemake script: pressure relaxation of the mixture's glasses at fixed phi (after Donev 2006, Fig. 13.7)."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_relaxation
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_relaxation([load_dataset(path) for path in snakemake.input])
save(fig, snakemake.output.pdf, snakemake.output.png)
