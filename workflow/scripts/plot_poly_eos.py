"""Snakemake script: fluid Z vs phi against BMCSL for every distribution and its equivalents."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.eos import plot_eos_vs_bmcsl
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
save(plot_eos_vs_bmcsl(load_dataset(snakemake.input[0], kind="eos_fluid_summary")), snakemake.output.pdf,
     snakemake.output.png)
logging.info("wrote %s", snakemake.output.pdf)
