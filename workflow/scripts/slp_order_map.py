"""Snakemake script: the order-map summary (phi, T, settings, verdict) of the SLP order-map packings."""

from hardpack.io import write_dataset
from hardpack.process import job_process
from hardpack.slp.ordermap import order_map_summary

job_process(snakemake.log[0])
write_dataset(order_map_summary(snakemake.input.packings, snakemake.input.verdicts), snakemake.output[0])
