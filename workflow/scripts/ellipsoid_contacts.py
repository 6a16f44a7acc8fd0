"""Snakemake script: contacts, backbone Z and nematic order of one jammed ellipsoid packing."""

import logging

from hardpack.geometry.ellipsoid_stats import ellipsoid_contacts, nematic_order
from hardpack.io import load_dataset, write_dataset
from hardpack.io.store import dataset_to_packing
from hardpack.process import job_process

job_process(snakemake.log[0])
jammed = load_dataset(snakemake.input[0])
packing = dataset_to_packing(jammed)
contacts = ellipsoid_contacts(packing, tol=snakemake.params.tol)
order, _ = nematic_order(packing)
ds = contacts.to_dataset()
ds.attrs.update(snakemake.params.attrs)
ds.attrs.update(
    hardpack_kind="ellipsoid_contacts", seed=int(snakemake.wildcards.seed), N=packing.n_particles,
    d=packing.dim, phi=packing.phi, z_mean=contacts.mean_contact_number, z_all=float(contacts.degree.mean()),
    rattler_fraction=contacts.n_rattlers / packing.n_particles, nematic_S=order,
    pressure=jammed.attrs["Z"], phi_J_est=jammed.attrs["phi_J_est"], collisions=jammed.attrs["collisions"],
    wall_time=jammed.attrs["wall_time"], source=str(snakemake.input[0]),
)
write_dataset(ds, snakemake.output[0], seed=int(snakemake.wildcards.seed))
logging.info("%s: phi %.6f, Z %.3f, rattlers %d, S %.3f", snakemake.output[0], packing.phi,
             contacts.mean_contact_number, contacts.n_rattlers, order)
