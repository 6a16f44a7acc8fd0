"""``hardpack structure PACKING.nc --out STRUCT.nc``: the standard structure analysis."""

from __future__ import annotations

import logging

import numpy as np

from hardpack.errors import InvalidInputError

log = logging.getLogger("hardpack.structure")


def cmd_structure(args) -> int:
    """g2, Z(l), S(k) with S(0), and order metrics of a packing, written as netCDF."""
    from hardpack.io import dataset_to_packing, load_dataset, write_dataset
    from hardpack.structure.analysis import analyse

    ds = load_dataset(args.packing, kind="packing")
    packing = dataset_to_packing(ds, source=str(args.packing), allow_overlap=True)
    rattlers = None
    if args.rattlers:
        if args.rattlers not in ds:
            raise InvalidInputError(
                f"{args.packing} has no variable {args.rattlers!r} to use as the rattler mask; "
                f"variables: {sorted(ds.data_vars)}")
        rattlers = np.asarray(ds[args.rattlers].values).astype(bool)
    out = analyse(packing, r_max=args.rmax, k_max=args.kmax, rattlers=rattlers,
                  contact_tol=args.contact_tol, gap_max=args.gap_max, dr=args.dr,
                  order=not args.no_order)
    write_dataset(out, args.out, attrs=dict(source=str(args.packing),
                                            rattler_mask=args.rattlers or ""))
    log.info("wrote %s", args.out)
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser("structure", help=cmd_structure.__doc__)
    p.add_argument("packing", help="packing netCDF file")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--rmax", type=float, default=None, help="g2 range (default 5 mean diameters)")
    p.add_argument("--dr", type=float, default=None, help="g2 bin width (default D/200)")
    p.add_argument("--kmax", type=float, default=None, help="S(k) range (default 20 / mean diameter)")
    p.add_argument("--contact-tol", type=float, default=1e-9,
                   help="relative gap below which a pair is a contact (delta peak)")
    p.add_argument("--gap-max", type=float, default=0.5, help="largest relative gap for Z(l)")
    p.add_argument("--rattlers", default=None, metavar="VAR",
                   help="boolean per-particle variable of the packing file flagging rattlers")
    p.add_argument("--no-order", action="store_true", help="skip the order metrics")
    p.set_defaults(func=cmd_structure)
