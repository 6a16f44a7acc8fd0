"""The netCDF store: packings <-> xarray Datasets, atomic writes, provenance, ensembles."""

from hardpack.io.provenance import provenance
from hardpack.io.store import (
    combine_ensemble,
    dataset_to_packing,
    load_dataset,
    load_judged_packing,
    load_judged_packings,
    load_packing,
    packing_to_dataset,
    save_packing,
    write_dataset,
)

__all__ = [
    "provenance", "packing_to_dataset", "dataset_to_packing", "save_packing", "load_packing",
    "load_dataset", "load_judged_packing", "load_judged_packings", "write_dataset", "combine_ensemble",
]
