"""Snakemake script: phi_J and contact number of the monodisperse LS ensembles vs dimension."""

from hardpack.io import load_dataset
from hardpack.plots.jamming import plot_jamming_vs_d
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
jammed = [load_dataset(p) for p in snakemake.input.jammed]
verdicts = [load_dataset(p) for p in snakemake.input.verdicts]
save(plot_jamming_vs_d(jammed, verdicts), snakemake.output.pdf, snakemake.output.png)
