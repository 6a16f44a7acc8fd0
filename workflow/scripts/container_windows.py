"""Snakemake script: sigma_phi of random spherical windows in periodic jammed packings vs 2R/D
(Donev 2006, Fig. 7.3)."""

import logging

from hardpack.io import load_packing, write_dataset
from hardpack.process import job_process
from hardpack.structure.containers import window_study

job_process(snakemake.log[0])
p = snakemake.params
ds = window_study([load_packing(path) for path in snakemake.input], n_radii=p.n_radii,
                  min_diameter=p.min_diameter, n_windows=p.n_windows, seed=p.seed)
ds = ds.assign_coords(seed=("sample", list(p.seeds)))
ds.attrs.update(ensemble=p.ensemble, fit_min_diameter=p.fit_min_diameter)
write_dataset(ds, snakemake.output[0])
logging.info("%s: 2R/D %.3g..%.3g, sigma_phi %.3g..%.3g", snakemake.output[0], ds.x.values[0], ds.x.values[-1],
             float(ds.sigma_phi.mean("sample")[0]), float(ds.sigma_phi.mean("sample")[-1]))
