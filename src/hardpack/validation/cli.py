"""``hardpack validate``: write the validation table (netCDF) and report (Markdown)."""

from __future__ import annotations

import logging

from hardpack.io import load_dataset, write_dataset
from hardpack.io.atomic import write_text
from hardpack.validation.analytic import hgrid_rows, moment_table_rows
from hardpack.validation.rows import to_dataset, to_markdown
from hardpack.validation.freeenergy import bcmd_rows
from hardpack.validation.packings import ls_rows, slp_mrj_rows
from hardpack.validation.slp import densest_rows

log = logging.getLogger(__name__)


def cmd_validate(args) -> int:
    """Validation table and report from the pipeline's summaries (each input optional)."""
    rows = moment_table_rows() + hgrid_rows()
    if args.slp_densest:
        rows += densest_rows(load_dataset(args.slp_densest))
    rows += ls_rows([load_dataset(p) for p in args.ls_summary or ()])
    rows += slp_mrj_rows([load_dataset(p) for p in args.slp_summary or ()])
    rows += bcmd_rows({ds.attrs["state"]: ds for ds in map(load_dataset, args.bcmd_summary or ())})
    write_dataset(to_dataset(rows), args.out_nc)
    write_text(args.out_md, to_markdown(rows))
    n_pass = sum(r.passed for r in rows)
    log.info("validation: %d of %d rows pass; wrote %s and %s", n_pass, len(rows), args.out_nc, args.out_md)
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser("validate", help=cmd_validate.__doc__)
    p.add_argument("--out-nc", required=True, help="validation table (netCDF)")
    p.add_argument("--out-md", required=True, help="readable report (Markdown)")
    p.add_argument("--slp-densest", help="summary of the SLP densest-packing runs (Table II)")
    p.add_argument("--ls-summary", action="append", help="LS jammed summary of an ensemble (repeatable)")
    p.add_argument("--slp-summary", action="append", help="SLP MRJ summary of an ensemble (repeatable)")
    p.add_argument("--bcmd-summary", action="append", help="BCMD FCC summary of one state (repeatable)")
    p.set_defaults(func=cmd_validate)
