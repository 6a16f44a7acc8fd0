"""Snakemake script: phi_J vs omega (sigma) for poly / bi / tri systems (one summary per family)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.eos import plot_phij_vs_width
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
summaries = [load_dataset(path, kind="eos_jam_summary") for path in snakemake.input]
save(plot_phij_vs_width(summaries), snakemake.output.pdf, snakemake.output.png)
logging.info("wrote %s", snakemake.output.pdf)
