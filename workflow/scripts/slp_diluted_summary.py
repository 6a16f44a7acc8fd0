"""Snakemake script: the diluted-MRJ summary (Torquato & Jiao 2010, Sec. VI) over (seed, round)."""

from hardpack.io import write_dataset
from hardpack.process import job_process
from hardpack.slp.diluted import diluted_summary

job_process(snakemake.log[0])
write_dataset(diluted_summary(snakemake.input.packings, snakemake.input.verdicts), snakemake.output[0])
