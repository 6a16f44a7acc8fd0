"""Snakemake script: the container packings over (N, seed), the Eq. 7.2 bulk extrapolation and the
periodic packings of the same protocol."""

import logging

from hardpack.io import load_dataset, write_dataset
from hardpack.process import job_process
from hardpack.structure.containers import container_summary

job_process(snakemake.log[0])
ds = container_summary([load_dataset(path) for path in snakemake.input.profiles], fit_min_n=snakemake.params.fit_min_n,
                       bulk=[load_dataset(path) for path in snakemake.input.bulk])
write_dataset(ds, snakemake.output[0])
logging.info("%s: %d packings; phi_0 = %.4f +- %.4f over %d packings of %d sizes", snakemake.output[0],
             ds.sizes["sample"], ds.attrs["phi0"], ds.attrs["phi0_err"], ds.attrs["n_fit"], ds.attrs["n_sizes_fit"])
logging.info("periodic packings of the protocol: phi = %.4f +- %.4f (%d)", ds.attrs["phi_bulk"],
             ds.attrs["phi_bulk_err"], ds.attrs["n_bulk"])
