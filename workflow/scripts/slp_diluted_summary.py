"""Snakemake script: the diluted-MRJ summary (Torquato & Jiao 2010, Sec. VI) over (seed, round)."""

import logging

from hardpack.io import write_dataset
from hardpack.slp.diluted import diluted_summary

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
write_dataset(diluted_summary(snakemake.input.packings, snakemake.input.verdicts), snakemake.output[0])
