"""``hardpack validate``: the validation table (netCDF), the report (Markdown) and the gate.

Each input is ``NAME=PATH``: NAME picks the row builder of :data:`ROW_BUILDERS` (one per study),
PATH is a summary Dataset the pipeline wrote. A builder receives every dataset given under its
name, in order. The analytic rows (moment tables, hierarchical-grid cost model) need no input.

The gate (:func:`hardpack.validation.rows.gate`): the command exits with status 1 when an
applicable row fails, when a documented deviation now passes, or when fewer than
``--min-applicable`` reproduction and analytic rows are applicable. ``--check TABLE.nc`` applies
the gate to a table written before (the pipeline writes the report first, so that a failing gate
keeps it).
"""

from __future__ import annotations

import logging
import sys

from hardpack.errors import InvalidInputError
from hardpack.io import load_dataset, write_dataset
from hardpack.io.atomic import write_text
from hardpack.validation.analytic import hgrid_rows, moment_table_rows
from hardpack.validation.containers import container_rows
from hardpack.validation.ellipsoids import crystal_rows, crystal_search_rows, ellipsoid_jamming_rows, ellipsoid_rows
from hardpack.validation.freeenergy import (
    bcmd_rows,
    density_rows,
    ellipse_ladder_rows,
    ellipse_rows,
    ladder_rows,
    simplex_rows,
)
from hardpack.validation.glass import (
    disk_crystal_rows,
    entropy_rows,
    eos_rows,
    freezing_rows,
    microsegregated_rows,
    relaxed_rows,
    smix_rows,
    soc_rows,
)
from hardpack.validation.jamming import jamming_rows, strict_ls_rows
from hardpack.validation.packings import ls_rows, slp_mrj_rows
from hardpack.validation.polydisperse import polydisperse_rows
from hardpack.validation.rows import from_dataset, gate, headline, to_dataset, to_markdown
from hardpack.validation.slp import densest_rows, diluted_rows, ls_densest_rows, mrj_jamming_rows, order_map_rows
from hardpack.validation.structure import structure_rows
from hardpack.validation.targets import load_targets

log = logging.getLogger(__name__)

#: the smallest number of applicable reproduction and analytic rows the gate accepts
MIN_APPLICABLE = 30

#: input name -> function(list of summary Datasets) -> list of Rows
ROW_BUILDERS = {
    "ls": ls_rows,
    "slp_mrj": slp_mrj_rows,
    "slp_densest": lambda datasets: [row for ds in datasets for row in densest_rows(ds)],
    "ls_densest": lambda datasets: [row for ds in datasets for row in ls_densest_rows(ds)],
    "slp_jamming": mrj_jamming_rows,
    "slp_order_map": lambda datasets: [row for ds in datasets for row in order_map_rows(ds)],
    "slp_diluted": lambda datasets: [row for ds in datasets for row in diluted_rows(ds)],
    "jamming": jamming_rows,
    "strict_ls": strict_ls_rows,
    "structure": structure_rows,
    "bcmd": lambda datasets: bcmd_rows({ds.attrs["state"]: ds for ds in datasets}),
    "bcmd_density": lambda datasets: density_rows(**{ds.attrs["state"]: ds for ds in datasets}),
    "bcmd_simplex": lambda datasets: [row for ds in datasets for row in simplex_rows(ds)],
    "bcmd_ladder": lambda datasets: [row for ds in datasets for row in ladder_rows(ds)],
    "bcmd_ellipse": lambda datasets: [row for ds in datasets for row in ellipse_rows(ds)],
    "bcmd_ellipse_ladder": lambda datasets: [row for ds in datasets for row in ellipse_ladder_rows(ds)],
    "polydisperse": polydisperse_rows,
    "glass_eos": lambda datasets: [row for ds in datasets for row in eos_rows(ds)],
    "glass_entropy": lambda datasets: [row for ds in datasets for row in entropy_rows(ds)],
    "glass_crystal": lambda datasets: _disk_crystal_rows(datasets),
    "glass_freezing": lambda datasets: [row for ds in datasets for row in freezing_rows(ds)],
    "glass_relaxed": lambda datasets: [row for ds in datasets for row in relaxed_rows(ds)],
    "glass_soc": lambda datasets: [row for ds in datasets for row in soc_rows(ds)],
    "glass_microsegregated": lambda datasets: [row for ds in datasets for row in microsegregated_rows(ds)],
    "ellipsoids": ellipsoid_rows,
    "ellipsoid_jamming": ellipsoid_jamming_rows,
    "ellipsoid_crystals": crystal_rows,
    "crystal_search": crystal_search_rows,
    "containers": container_rows,
}


def _disk_crystal_rows(datasets) -> list:
    eos = [ds for ds in datasets if ds.attrs.get("hardpack_kind") == "glass_eos"]
    bcmd = [ds for ds in datasets if ds.attrs.get("hardpack_kind") != "glass_eos"]
    if len(eos) != 1 or len(bcmd) != 1:
        raise InvalidInputError("glass_crystal takes the crystal's BCMD summary and the monodisperse "
                                f"EOS summary (one each), got {len(bcmd)} and {len(eos)}")
    return disk_crystal_rows(bcmd[0], eos[0])


def parse_inputs(items: list[str]) -> dict[str, list[str]]:
    """Group the NAME=PATH inputs of ``hardpack validate`` by name.

    ``["ls=a.nc", "ls=b.nc", "bcmd=c.nc"]`` -> ``{"ls": ["a.nc", "b.nc"], "bcmd": ["c.nc"]}``.

    Parameters
    ----------
    items : list of str
        NAME=PATH items, NAME one of :data:`ROW_BUILDERS`.

    Returns
    -------
    dict
        name -> paths, in the order given.

    Raises
    ------
    InvalidInputError
        If an item is not NAME=PATH or names an unknown input.
    """
    grouped: dict[str, list[str]] = {}
    for item in items:
        name, sep, path = item.partition("=")
        if not sep or not path:
            raise InvalidInputError(f"validation input {item!r} is not NAME=PATH (e.g. ls=summary.nc)")
        if name not in ROW_BUILDERS:
            raise InvalidInputError(f"unknown validation input name {name!r}; known: {', '.join(ROW_BUILDERS)}")
        grouped.setdefault(name, []).append(path)
    return grouped


def build_rows(inputs: dict[str, list[str]]) -> list:
    """Every validation row: the analytic ones and those of each named summary.

    Parameters
    ----------
    inputs : dict
        name -> paths of summary datasets (:func:`parse_inputs`).

    Returns
    -------
    list of Row
        The analytic rows (moments, hierarchical-grid cost, mixing entropy), then the rows each
        input's builder in :data:`ROW_BUILDERS` makes from its datasets.
    """
    rows = moment_table_rows() + hgrid_rows() + smix_rows()
    for name, paths in inputs.items():
        rows += ROW_BUILDERS[name]([load_dataset(p) for p in paths])
    return rows


def _report_gate(rows, min_applicable: int) -> int:
    problems = gate(rows, min_applicable)
    for line in headline(rows):
        log.info("validation %s", line.removeprefix("- ").replace("**", ""))
    if problems:
        print(f"hardpack validate: the gate failed ({len(problems)} problem(s)):", file=sys.stderr)
        for p in problems:
            print(f"  {p}", file=sys.stderr)
        return 1
    log.info("validation gate passed")
    return 0


def cmd_validate(args) -> int:
    """Validation table, report and gate from the pipeline's summaries (NAME=PATH inputs).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack validate``.

    Returns
    -------
    int
        Exit status: 0, or that of the gate (non-zero when it fails).
    """
    if args.check:
        if args.inputs or args.out_nc or args.out_md:
            raise InvalidInputError("--check TABLE.nc takes no inputs and no --out-nc / --out-md")
        return _report_gate(from_dataset(load_dataset(args.check, kind="validation")), args.min_applicable)
    if not (args.out_nc and args.out_md):
        raise InvalidInputError("give --out-nc and --out-md (or --check TABLE.nc to gate a written table)")
    rows = build_rows(parse_inputs(args.inputs))
    measured = {r.target for r in rows}
    unmeasured = [t for tid, t in load_targets().items() if tid not in measured]
    write_dataset(to_dataset(rows), args.out_nc)
    write_text(args.out_md, to_markdown(rows, gate(rows, args.min_applicable), unmeasured))
    log.info("wrote %s and %s", args.out_nc, args.out_md)
    return 0 if args.no_gate else _report_gate(rows, args.min_applicable)


def register(subparsers) -> None:
    """Add the subcommand ``validate`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    p = subparsers.add_parser("validate", help=cmd_validate.__doc__.split("\n\n")[0])
    p.add_argument("inputs", nargs="*", metavar="NAME=PATH",
                   help=f"summary datasets by row builder ({', '.join(ROW_BUILDERS)}); repeatable")
    p.add_argument("--out-nc", help="validation table (netCDF)")
    p.add_argument("--out-md", help="readable report (Markdown)")
    p.add_argument("--check", metavar="TABLE.nc", help="apply the gate to a validation table written before")
    p.add_argument("--min-applicable", type=int, default=MIN_APPLICABLE,
                   help=f"fewest applicable reproduction and analytic rows the gate accepts (default {MIN_APPLICABLE})")
    p.add_argument("--no-gate", action="store_true",
                   help="write the table and report and exit 0 whatever the rows say (the pipeline "
                        "gates in a separate step, so that a failing gate keeps the report)")
    p.set_defaults(func=cmd_validate)
