"""Snakemake script: SLP vs LS jamming densities per ensemble, plus SLP-only systems (Table I)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.slp import plot_slp_vs_ls
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
pairs = {}
for slp_path, ls_path in zip(snakemake.input.slp, snakemake.input.ls):
    slp, ls = load_dataset(slp_path, kind="ensemble"), load_dataset(ls_path, kind="ensemble")
    pairs[slp.attrs["ensemble"]] = (slp, ls)
for path in snakemake.input.systems:
    slp = load_dataset(path, kind="ensemble")
    pairs[slp.attrs["ensemble"]] = (slp, None)
save(plot_slp_vs_ls(pairs), snakemake.output.pdf, snakemake.output.png)
