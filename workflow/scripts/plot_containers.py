"""Snakemake script: a figure of the container study (params.kind: profile, ellipsoid_profile,
extrapolation, windows)."""

from hardpack.io import load_dataset
from hardpack.plots.containers import (
    plot_ellipsoid_radial_profiles,
    plot_extrapolation,
    plot_radial_profile,
    plot_window_fluctuations,
)
from hardpack.plots.style import save
from hardpack.process import job_process

job_process(snakemake.log[0])
kind = snakemake.params.kind
datasets = [load_dataset(path) for path in snakemake.input]
if kind == "profile":
    fig = plot_radial_profile(datasets)
elif kind == "ellipsoid_profile":
    fig = plot_ellipsoid_radial_profiles(datasets)
elif kind == "extrapolation":
    fig = plot_extrapolation(datasets[0], datasets[1:])  # spheres, then the ellipsoid shapes
else:
    fig = plot_window_fluctuations(datasets[0])
save(fig, snakemake.output.pdf, snakemake.output.png)
