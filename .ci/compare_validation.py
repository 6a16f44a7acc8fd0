"""CI check: the validation datasets of two runs of the smoke DAG (local, and through SLURM) agree.

Compared row by row (rows keyed by target and label, in the same order): the published value,
the tolerance, the status (pass, fail, n/a, ...) and the tolerance origin must be equal; the
reproduced value and its uncertainty equal or within float noise (relative 1e-9; NaN matches
NaN). The free-text `detail` is not compared. Also the headline counts (`n_*` attributes).

    python .ci/compare_validation.py LOCAL.nc SLURM.nc
"""

import sys

import numpy as np
import xarray as xr

RTOL = 1e-9


def main(a_path: str, b_path: str) -> None:
    a, b = xr.load_dataset(a_path), xr.load_dataset(b_path)
    problems = []
    keys_a = list(zip(a["target"].values, a["label"].values))
    keys_b = list(zip(b["target"].values, b["label"].values))
    if keys_a != keys_b:
        sys.exit(f"the runs have different rows: {sorted(set(keys_a) ^ set(keys_b))[:10]}")
    for var in ("status", "tolerance_origin", "kind"):
        for i in np.flatnonzero(a[var].values != b[var].values):
            problems.append(f"{keys_a[i]}: {var} {a[var].values[i]!r} != {b[var].values[i]!r}")
    for var in ("published", "tolerance", "reproduced", "uncertainty"):
        x, y = a[var].values, b[var].values
        same = np.isclose(x, y, rtol=RTOL, atol=0.0) | (np.isnan(x) & np.isnan(y))
        for i in np.flatnonzero(~same):
            problems.append(f"{keys_a[i]}: {var} {x[i]!r} != {y[i]!r}")
    counts = sorted(k for k in a.attrs if k.startswith("n_"))
    for key in counts:
        if a.attrs[key] != b.attrs.get(key):
            problems.append(f"attribute {key}: {a.attrs[key]} != {b.attrs.get(key)}")
    if problems:
        sys.exit("the validation datasets differ:\n  " + "\n  ".join(problems))
    reproduced = int(np.sum(~np.isnan(a["reproduced"].values)))
    print(f"validation datasets agree: {len(keys_a)} rows ({reproduced} reproduced values within relative "
          f"{RTOL:g}, statuses and published values equal), {len(counts)} headline counts equal")


if __name__ == "__main__":
    main(*sys.argv[1:])
