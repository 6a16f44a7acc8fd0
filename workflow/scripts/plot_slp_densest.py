"""Snakemake script: Table II figure from the SLP (and LS) densest-packing summaries."""

from hardpack.io import load_dataset
from hardpack.plots.slp import plot_densest
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
ls = [load_dataset(path, kind="ensemble") for path in snakemake.input.ls]
save(plot_densest(load_dataset(snakemake.input.slp, kind="ensemble"), ls[0] if ls else None),
     snakemake.output.pdf, snakemake.output.png)
