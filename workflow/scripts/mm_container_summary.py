"""Snakemake script: the M&M container packings over (N, seed) and their Eq. 7.2 bulk extrapolation
(hardpack.structure.containers.ellipsoid_container_summary)."""

import logging

from hardpack.io import load_dataset, load_packing, write_dataset
from hardpack.structure.containers import ellipsoid_container_summary

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
paths = list(snakemake.input)
ds = ellipsoid_container_summary([load_packing(p) for p in paths],
                                 [int(load_dataset(p).attrs["seed"]) for p in paths],
                                 fit_min_n=snakemake.params.fit_min_n)
write_dataset(ds, snakemake.output[0])
logging.info("%s: %d packings; phi_0 = %.4f +- %.4f over %d packings of %d sizes", snakemake.output[0],
             ds.sizes["sample"], ds.attrs["phi0"], ds.attrs["phi0_err"], ds.attrs["n_fit"], ds.attrs["n_sizes_fit"])
