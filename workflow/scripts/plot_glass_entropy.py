"""Snakemake script: excess free energies of liquid and SOC glasses, s_c - s_mix vs phi."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_entropy
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_entropy(load_dataset(snakemake.input.binary), load_dataset(snakemake.input.mono))
save(fig, snakemake.output.pdf, snakemake.output.png)
