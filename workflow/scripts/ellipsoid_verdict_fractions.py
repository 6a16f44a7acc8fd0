"""Snakemake script: per-shape fractions of jammed packings and of the order that decided them."""

import logging

from hardpack.io import load_dataset, write_dataset
from hardpack.jamming.ellipsoid_verdicts import verdict_fractions
from hardpack.process import job_process

job_process(snakemake.log[0])
fractions = verdict_fractions(load_dataset(snakemake.input[0]))
write_dataset(fractions, snakemake.output[0])
logging.info("%s:\n%s", snakemake.output[0], fractions.to_dataframe().to_string())
