"""Snakemake script: the fully phase-separated crystal of the mixture and its decompressions (after
Donev 2006, Figs. 13.4-13.5)."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_separated
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_separated(load_dataset(snakemake.input.freezing),
                           [load_dataset(path) for path in snakemake.input.decompressions])
save(fig, snakemake.output.pdf, snakemake.output.png)
