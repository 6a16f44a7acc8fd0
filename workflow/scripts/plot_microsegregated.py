"""Snakemake script: s_c vs phi_J of the micro-segregated packings (after Donev 2006, Fig. 13.16)."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_microsegregated
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_microsegregated(load_dataset(snakemake.input[0], kind="microsegregated_summary"))
save(fig, snakemake.output.pdf, snakemake.output.png)
