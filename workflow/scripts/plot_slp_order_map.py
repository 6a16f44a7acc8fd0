"""Snakemake script: the phi-T order map figure (Torquato & Jiao Fig. 6) from its summaries."""

from hardpack.io import load_dataset
from hardpack.plots.slp import plot_order_map
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
order_map = [load_dataset(path, kind="slp_order_map") for path in snakemake.input.order_map]
diluted = [load_dataset(path, kind="slp_diluted") for path in snakemake.input.diluted]
fig = plot_order_map(order_map[0] if order_map else None, diluted[0] if diluted else None)
save(fig, snakemake.output.pdf, snakemake.output.png)
