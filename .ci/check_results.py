"""CI check: every netCDF under results/ opens as a hardpack dataset, every figure is a PDF."""

import sys
from pathlib import Path

from hardpack.io import load_dataset

results = Path("results")
nc = sorted(results.rglob("*.nc"))
pdf = sorted((results / "figures").glob("*.pdf"))
if not nc or not pdf:
    sys.exit(f"smoke DAG produced {len(nc)} netCDF files and {len(pdf)} figures; expected both > 0")
for path in nc:
    load_dataset(path)
for path in pdf:
    if not path.read_bytes().startswith(b"%PDF"):
        sys.exit(f"{path} is not a PDF")
print(f"checked {len(nc)} netCDF files and {len(pdf)} figures")
