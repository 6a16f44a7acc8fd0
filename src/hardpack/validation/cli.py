"""``hardpack validate``: write the validation table (netCDF) and report (Markdown).

Each input is ``NAME=PATH``: NAME picks the row builder of :data:`ROW_BUILDERS` (one per study),
PATH is a summary Dataset the pipeline wrote. A builder receives every dataset given under its
name, in order. The analytic rows (moment tables, hierarchical-grid cost model) need no input.
"""

from __future__ import annotations

import logging

from hardpack.errors import InvalidInputError
from hardpack.io import load_dataset, write_dataset
from hardpack.io.atomic import write_text
from hardpack.validation.analytic import hgrid_rows, moment_table_rows
from hardpack.validation.freeenergy import (
    bcmd_rows,
    density_rows,
    ladder_rows,
    simplex_rows,
)
from hardpack.validation.jamming import jamming_rows
from hardpack.validation.packings import ls_rows, slp_mrj_rows
from hardpack.validation.polydisperse import polydisperse_rows
from hardpack.validation.rows import to_dataset, to_markdown
from hardpack.validation.slp import densest_rows, mrj_jamming_rows, order_map_rows
from hardpack.validation.structure import structure_rows

log = logging.getLogger(__name__)

#: input name -> function(list of summary Datasets) -> list of Rows
ROW_BUILDERS = {
    "ls": ls_rows,
    "slp_mrj": slp_mrj_rows,
    "slp_densest": lambda datasets: [row for ds in datasets for row in densest_rows(ds)],
    "slp_jamming": mrj_jamming_rows,
    "slp_order_map": lambda datasets: [row for ds in datasets for row in order_map_rows(ds)],
    "jamming": jamming_rows,
    "structure": structure_rows,
    "bcmd": lambda datasets: bcmd_rows({ds.attrs["state"]: ds for ds in datasets}),
    "bcmd_density": lambda datasets: density_rows(**{ds.attrs["state"]: ds for ds in datasets}),
    "bcmd_simplex": lambda datasets: [row for ds in datasets for row in simplex_rows(ds)],
    "bcmd_ladder": lambda datasets: [row for ds in datasets for row in ladder_rows(ds)],
    "polydisperse": polydisperse_rows,
}


def parse_inputs(items: list[str]) -> dict[str, list[str]]:
    """``["ls=a.nc", "ls=b.nc", "bcmd=c.nc"]`` -> ``{"ls": ["a.nc", "b.nc"], "bcmd": ["c.nc"]}``."""
    grouped: dict[str, list[str]] = {}
    for item in items:
        name, sep, path = item.partition("=")
        if not sep or not path:
            raise InvalidInputError(f"validation input {item!r} is not NAME=PATH (e.g. ls=summary.nc)")
        if name not in ROW_BUILDERS:
            raise InvalidInputError(f"unknown validation input name {name!r}; known: {', '.join(ROW_BUILDERS)}")
        grouped.setdefault(name, []).append(path)
    return grouped


def cmd_validate(args) -> int:
    """Validation table and report from the pipeline's summaries (NAME=PATH inputs)."""
    rows = moment_table_rows() + hgrid_rows()
    for name, paths in parse_inputs(args.inputs).items():
        rows += ROW_BUILDERS[name]([load_dataset(p) for p in paths])
    write_dataset(to_dataset(rows), args.out_nc)
    write_text(args.out_md, to_markdown(rows))
    n_pass = sum(r.passed for r in rows)
    log.info("validation: %d of %d rows pass; wrote %s and %s", n_pass, len(rows), args.out_nc, args.out_md)
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser("validate", help=cmd_validate.__doc__)
    p.add_argument("inputs", nargs="*", metavar="NAME=PATH",
                   help=f"summary datasets by row builder ({', '.join(ROW_BUILDERS)}); repeatable")
    p.add_argument("--out-nc", required=True, help="validation table (netCDF)")
    p.add_argument("--out-md", required=True, help="readable report (Markdown)")
    p.set_defaults(func=cmd_validate)
