"""Snakemake script: cell-wall pressure of the SOC glasses vs cell size (after Donev 2006, Fig. 13.10)."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_cell_pressure
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_cell_pressure([load_dataset(path) for path in snakemake.input.binary],
                               [load_dataset(path) for path in snakemake.input.mono])
save(fig, snakemake.output.pdf, snakemake.output.png)
