"""Snakemake script: SOC solids of the mixture against its slowest compression (after Donev 2006, Fig. 13.9)."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_soc
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_soc(load_dataset(snakemake.input.eos), [load_dataset(path) for path in snakemake.input.soc],
                     load_dataset(snakemake.input.summary))
save(fig, snakemake.output.pdf, snakemake.output.png)
