"""Snakemake script: BCMD free energies of FCC vs system size."""

from hardpack.io import load_dataset
from hardpack.plots.freeenergy import plot_fcc_finite_size
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
summaries = {load_dataset(p).attrs["state"]: load_dataset(p) for p in snakemake.input}
save(plot_fcc_finite_size(summaries), snakemake.output.pdf, snakemake.output.png)
