"""Snakemake script: a figure of the container study (params.kind: profile, extrapolation, windows)."""

import logging

from hardpack.io import load_dataset
from hardpack.plots.containers import plot_extrapolation, plot_radial_profile, plot_window_fluctuations
from hardpack.plots.style import save

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO)
kind = snakemake.params.kind
datasets = [load_dataset(path) for path in snakemake.input]
if kind == "profile":
    fig = plot_radial_profile(datasets)
elif kind == "extrapolation":
    fig = plot_extrapolation(datasets[0], datasets[1:])  # spheres, then the ellipsoid shapes
else:
    fig = plot_window_fluctuations(datasets[0])
save(fig, snakemake.output.pdf, snakemake.output.png)
