"""Snakemake script: free energy of monodisperse disks by EOS integration and by BCMD of the crystal."""

from hardpack.io import load_dataset
from hardpack.plots.glass import plot_glass_crystal
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
fig = plot_glass_crystal(load_dataset(snakemake.input.eos), load_dataset(snakemake.input.crystal))
save(fig, snakemake.output.pdf, snakemake.output.png)
