"""Snakemake script: radial density profile phi(r), average density, a/R and core density of one
jammed packing in a spherical container (Donev 2006, Sec. 7.3, Figs. 7.5-7.6): exact for spheres,
exact to 1e-10 of a particle's volume for ellipsoids."""

import logging
import math

from hardpack.io import load_dataset, write_dataset
from hardpack.io.store import dataset_to_packing
from hardpack.process import job_process
from hardpack.structure.containers import (
    core_density,
    ellipsoid_radial_density_profile,
    length_unit,
    radial_density_profile,
)

job_process(snakemake.log[0])
jammed = load_dataset(snakemake.input[0])
packing = dataset_to_packing(jammed)
a, radius = length_unit(packing), packing.boundary.radius
margin = snakemake.params.core_margin
profile_of = ellipsoid_radial_density_profile if packing.shape.kind == "ellipsoid" else radial_density_profile
profile = profile_of(packing, n_shells=math.ceil(radius / (snakemake.params.shell_width * a)))
seed = int(snakemake.wildcards.seed)
# a container of radius R <= margin a has no core: NaN, said in the log (the core row reads the largest N)
phi_core = core_density(packing, margin) if radius > margin * a else float("nan")
profile.attrs.update(
    seed=seed, N=packing.n_particles, phi=packing.phi, a_over_R=a / radius,
    phi_core=phi_core, core_margin=margin, shell_width=snakemake.params.shell_width,
    pressure=jammed.attrs["Z"], collisions=jammed.attrs["collisions"], wall_time=jammed.attrs["wall_time"],
    source=str(snakemake.input[0]),
)
shape_name = getattr(snakemake.params, "shape_name", None)  # ellipsoids: the config's shape
if shape_name is not None:
    profile.attrs["shape_name"] = shape_name
write_dataset(profile, snakemake.output[0], seed=seed)
logging.info("%s: N %d, a/R %.5f, phi_avg %.6f, core (r <= R - %g a) %.6f (NaN: no core)", snakemake.output[0],
             packing.n_particles, a / radius, packing.phi, margin, profile.attrs["phi_core"])
