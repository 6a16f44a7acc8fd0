"""Snakemake script: a deforming-cell LS disk packing with its contact forces (after Donev 2006, Fig. 4.15)."""

from hardpack.io import load_judged_packing
from hardpack.plots.jamming import plot_jammed_disks
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
_, packing, verdict = load_judged_packing(snakemake.input.packing, snakemake.input.verdict)
save(plot_jammed_disks(packing, verdict), snakemake.output.pdf, snakemake.output.png)
