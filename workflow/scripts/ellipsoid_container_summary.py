"""Snakemake script: the container packings of one ellipsoid shape over (N, seed), their core
densities (from their radial profiles, in the same order) and their Eq. 7.2 bulk extrapolation
(hardpack.structure.containers.ellipsoid_container_summary), with the shape's name from the
config (``shape_name``, which the validation rows read)."""

import logging

from hardpack.io import load_dataset, load_packing, write_dataset
from hardpack.process import job_process
from hardpack.structure.containers import ellipsoid_container_summary

job_process(snakemake.log[0])
paths = list(snakemake.input.packings)
attrs = [load_dataset(p).attrs for p in paths]
ds = ellipsoid_container_summary([load_packing(p) for p in paths], [int(a["seed"]) for a in attrs],
                                 fit_min_n=snakemake.params.fit_min_n,
                                 profiles=[load_dataset(p) for p in snakemake.input.profiles])
ds.attrs["shape_name"] = snakemake.params.shape_name  # the validation row's key (config shapes)
write_dataset(ds, snakemake.output[0])
logging.info("%s: %d packings; phi_0 = %.4f +- %.4f over %d packings of %d sizes", snakemake.output[0],
             ds.sizes["sample"], ds.attrs["phi0"], ds.attrs["phi0_err"], ds.attrs["n_fit"], ds.attrs["n_sizes_fit"])
