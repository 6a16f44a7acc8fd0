"""Snakemake script: one structure figure (snakemake.params.kind) over the ensembles' seeds, grouped
by the structure datasets' ``ensemble`` attribute."""

from collections import defaultdict

from hardpack.io import load_dataset
from hardpack.plots import structure
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
ensembles = defaultdict(list)
for path in snakemake.input:
    ds = load_dataset(path, kind="structure")
    ensembles[ds.attrs["ensemble"]].append(ds)
plot = {"g2": structure.plot_g2_near_contact, "zl": structure.plot_coordination,
        "sk": structure.plot_structure_factor, "channels": structure.plot_channels}[snakemake.params.kind]
save(plot(dict(ensembles)), snakemake.output.pdf, snakemake.output.png)
