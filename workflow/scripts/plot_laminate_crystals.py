"""Snakemake script: density of the laminate crystals vs aspect ratio (after Donev 2006, Fig. 8.2)."""

from hardpack.io import load_dataset
from hardpack.plots.ellipsoids import plot_laminate_family
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
family = load_dataset(snakemake.input.family)
searches = [load_dataset(path) for path in snakemake.input.searches]
save(plot_laminate_family(family, searches), snakemake.output.pdf, snakemake.output.png)
