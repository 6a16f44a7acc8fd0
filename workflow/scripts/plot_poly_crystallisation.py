"""Snakemake script: slow runs of the polydisperse study, phi_J and large-species crystallinity vs omega."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.eos import plot_crystallisation
from hardpack.plots.style import save
from hardpack.process import job_process
from hardpack.validation.polydisperse import CRYSTALLISED

job_process(snakemake.log[0])
summary = load_dataset(snakemake.input[0], kind="eos_jam_summary")
save(plot_crystallisation(summary, CRYSTALLISED), snakemake.output.pdf, snakemake.output.png)
logging.info("wrote %s", snakemake.output.pdf)
