"""Snakemake script: a rendered jammed packing of M&M-shaped spheroids."""

from hardpack.io import load_packing
from hardpack.plots.ellipsoids import plot_snapshot
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
save(plot_snapshot(load_packing(snakemake.input[0])), snakemake.output.pdf, snakemake.output.png)
