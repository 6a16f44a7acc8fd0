"""Snakemake script: SLP vs LS jamming densities per ensemble, plus SLP-only systems (Table I).

SLP and LS summaries are paired by their ``ensemble`` attribute; an SLP system without an LS
ensemble of its name is drawn alone."""

from hardpack.io import load_dataset
from hardpack.plots.slp import plot_slp_vs_ls
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
ls = {ds.attrs["ensemble"]: ds for ds in (load_dataset(p, kind="ensemble") for p in snakemake.input.ls)}
pairs = {}
for path in snakemake.input.slp:
    slp = load_dataset(path, kind="ensemble")
    pairs[slp.attrs["ensemble"]] = (slp, ls.get(slp.attrs["ensemble"]))
save(plot_slp_vs_ls(pairs), snakemake.output.pdf, snakemake.output.png)
