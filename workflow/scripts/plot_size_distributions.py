"""Snakemake script: size-distribution figure from the ensemble summaries."""

import logging

from hardpack.distributions import from_spec
from hardpack.io import load_dataset
from hardpack.plots.distributions import plot_size_distributions
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
samples = {}
for path in snakemake.input:
    ds = load_dataset(path, kind="ensemble")
    name = ds.attrs["ensemble"]
    samples[name] = (ds["radius"].values.ravel(), from_spec(snakemake.params.distributions[name]))
save(plot_size_distributions(samples), snakemake.output.pdf, snakemake.output.png)
logging.info("wrote %s", snakemake.output.pdf)
