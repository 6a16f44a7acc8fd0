"""Snakemake script: LS growth-rate scan figures (snakemake.wildcards.kind = phij | eos)."""

from hardpack.io import load_dataset
from hardpack.plots.md import plot_rate_eos, plot_rate_phij
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
series = [load_dataset(p, kind="md_timeseries") for p in snakemake.input]
plot = {"phij": plot_rate_phij, "eos": plot_rate_eos}[snakemake.wildcards.kind]
save(plot(series), snakemake.output.pdf, snakemake.output.png)
