"""Snakemake script: phi~_J(phi) of the glass compressions with Eqs. 13.3-13.4."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_eos
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_eos(load_dataset(snakemake.input.binary), load_dataset(snakemake.input.mono))
save(fig, snakemake.output.pdf, snakemake.output.png)
