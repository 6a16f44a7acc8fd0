"""Snakemake script: FCC free energy vs density (BCMD, EOS integration, cell limit)."""

from hardpack.io import load_dataset
from hardpack.plots.freeenergy import plot_fcc_density
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_fcc_density(load_dataset(snakemake.input.bcmd), load_dataset(snakemake.input.eos))
save(fig, snakemake.output.pdf, snakemake.output.png)
