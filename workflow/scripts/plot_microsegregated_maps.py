"""Snakemake script: phi_J(R, nu) and s_c(R, nu) over the config's Matérn grid (after Donev 2006, Fig. 13.17)."""

import logging

from hardpack.glass.microsegregated import grid_maps
from hardpack.io import load_dataset
from hardpack.plots.glass import plot_microsegregated_maps
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
maps = grid_maps(load_dataset(snakemake.input[0], kind="microsegregated_summary"), snakemake.params.R,
                 snakemake.params.nu)
logging.info("%d of %d grid cells missing; off the grid: %s", maps.attrs["missing_cells"],
             maps.sizes["R"] * maps.sizes["nu"], maps.attrs["off_grid"] or "none")
save(plot_microsegregated_maps(maps), snakemake.output.pdf, snakemake.output.png)
