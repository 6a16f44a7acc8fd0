"""``hardpack eos-equivalents``: moments and bi-/tridisperse equivalents of a distribution family.

Writes one netCDF Dataset (``hardpack_kind = "eos_equivalents"``) over the family parameter
(omega for uniform_size / uniform_volume / power_law, sigma for lognormal): O1, O2, delta,
skewness, kurtosis, the bidisperse equivalent (n1, R; Table 3.1) and the maximally equivalent
tridisperse system (n1, n2, delta1, delta2 and radii a1 >= a2 >= a3 in units of <a>; Tables 3.3-3.4).
"""

from __future__ import annotations

import logging

import numpy as np
import xarray as xr

from hardpack.distributions import from_spec
from hardpack.eos import moments as mo
from hardpack.errors import InvalidInputError

log = logging.getLogger(__name__)

FAMILIES = {"uniform_size": "omega", "uniform_volume": "omega", "power_law": "omega", "lognormal": "sigma"}


def equivalents_dataset(kind: str, values, alpha: float | None = None) -> xr.Dataset:
    """The table for ``kind`` at each parameter value (see module docstring)."""
    if kind not in FAMILIES:
        raise InvalidInputError(f"unknown family {kind!r}; choose one of {sorted(FAMILIES)}")
    if (kind == "power_law") != (alpha is not None):
        raise InvalidInputError("--alpha is required for power_law and only allowed there")
    param = FAMILIES[kind]
    names = (
        "O1",
        "O2",
        "delta",
        "skewness",
        "kurtosis",
        "bi_n1",
        "bi_R",
        "tri_n1",
        "tri_n2",
        "tri_delta1",
        "tri_delta2",
    )
    table = {name: [] for name in names}
    radii = []
    for value in values:
        spec = {"kind": kind, param: float(value)} | ({"alpha": alpha} if alpha is not None else {})
        dist = from_spec(spec)
        bi, tri = mo.equivalent_bidisperse(dist), mo.equivalent_tridisperse(dist)
        row = (
            *mo.dimensionless_moments(dist),
            mo.polydispersity(dist),
            mo.skewness(dist),
            mo.kurtosis(dist),
            bi.n1,
            bi.R,
            tri.n1,
            tri.n2,
            tri.delta1,
            tri.delta2,
        )
        for name, v in zip(names, row):
            table[name].append(v)
        radii.append(tri.radii)
    coords = {param: np.asarray(values, float), "species": [1, 2, 3]}
    data = {name: ((param,), np.array(v)) for name, v in table.items()}
    data["tri_radii"] = ((param, "species"), np.array(radii))
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(hardpack_kind="eos_equivalents", family=kind, source="Ogarko Tables 3.1, 3.3, 3.4")
    if alpha is not None:
        ds.attrs["alpha"] = alpha
    return ds


def cmd_equivalents(args) -> int:
    """Moments, O1/O2 and bi-/tridisperse equivalents of a distribution family (Ogarko Tables 3.1-3.4)."""
    from hardpack.io import write_dataset

    ds = equivalents_dataset(args.kind, args.values, args.alpha)
    write_dataset(ds, args.out, config={"kind": args.kind, "values": list(args.values), "alpha": args.alpha})
    log.info("wrote %s (%d %s values)", args.out, len(args.values), FAMILIES[args.kind])
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser("eos-equivalents", help=cmd_equivalents.__doc__)
    p.add_argument("--kind", required=True, choices=sorted(FAMILIES), help="distribution family")
    p.add_argument("--values", type=float, nargs="+", required=True, help="omega (or sigma for lognormal) values")
    p.add_argument("--alpha", type=float, help="exponent of the power_law family")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_equivalents)
