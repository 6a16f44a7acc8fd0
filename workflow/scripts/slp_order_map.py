"""Snakemake script: the order-map summary (phi, T, settings, verdict) of the SLP order-map packings."""

import logging

from hardpack.io import write_dataset
from hardpack.slp.ordermap import order_map_summary

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
write_dataset(order_map_summary(snakemake.input.packings, snakemake.input.verdicts), snakemake.output[0])
