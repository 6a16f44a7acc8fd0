"""``hardpack structure PACKING.nc --out STRUCT.nc``: the standard structure analysis."""

from __future__ import annotations

import logging

import numpy as np

from hardpack.errors import InvalidInputError

log = logging.getLogger("hardpack.structure")


def cmd_structure(args) -> int:
    """g2, Z(l), S(k) with S(0), and order metrics of a packing, written as netCDF.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack structure``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import dataset_to_packing, load_dataset, write_dataset
    from hardpack.structure.analysis import analyse

    ds = load_dataset(args.packing, kind="packing")
    packing = dataset_to_packing(ds, source=str(args.packing))
    rattlers, no_backbone = None, {}
    if args.jamming:
        verdict = load_dataset(args.jamming, kind="jamming")
        if "rattler" not in verdict or verdict.sizes.get("particle") != packing.n_particles:
            raise InvalidInputError(
                f"{args.jamming} has no per-particle 'rattler' mask for the {packing.n_particles} "
                f"particles of {args.packing}; pass the output of `hardpack verify` on that packing")
        rattlers = np.asarray(verdict["rattler"].values).astype(bool)
        if rattlers.all():  # no backbone: its quantities do not exist (not those of all particles)
            no_backbone = dict(backbone="none: the jamming verdict flags every particle as a rattler",
                               jamming_verdict=str(verdict.attrs.get("verdict", "not jammed")),
                               n_rattlers=int(rattlers.sum()))
            log.warning("%s flags all %d particles as rattlers (verdict: %s): no backbone, so the "
                        "backbone's Z(l) and near-contact fit are left out (alpha = NaN)",
                        args.jamming, rattlers.size, no_backbone["jamming_verdict"])
    out = analyse(packing, r_max=args.rmax, k_max=args.kmax, rattlers=None if no_backbone else rattlers,
                  contact_tol=args.contact_tol, gap_max=args.gap_max, dr=args.dr,
                  order=not args.no_order)
    if no_backbone:
        for name in ("alpha", "alpha_err", "alpha_amplitude"):  # the fit is of the backbone
            out[name] = np.nan
    write_dataset(out, args.out, attrs=dict(args.attr or [], source=str(args.packing),
                                            rattler_mask=str(args.jamming) if args.jamming else "none",
                                            **no_backbone))
    log.info("wrote %s", args.out)
    return 0


def register(subparsers) -> None:
    """Add the subcommand ``structure`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    from hardpack.cli import _key_value

    p = subparsers.add_parser("structure", help=cmd_structure.__doc__.split("\n\n")[0])
    p.add_argument("packing", help="packing netCDF file")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--rmax", type=float, default=None, help="g2 range (default 5 mean diameters)")
    p.add_argument("--dr", type=float, default=None, help="g2 bin width (default D/200)")
    p.add_argument("--kmax", type=float, default=None, help="S(k) range (default 20 / mean diameter)")
    p.add_argument("--contact-tol", type=float, default=1e-9,
                   help="relative gap below which a pair is a contact (delta peak)")
    p.add_argument("--gap-max", type=float, default=0.5, help="largest relative gap for Z(l)")
    p.add_argument("--jamming", default=None, metavar="VERDICT.nc",
                   help="jamming verdict of this packing (hardpack verify) whose rattlers are excluded")
    p.add_argument("--no-order", action="store_true", help="skip the order metrics")
    p.add_argument("--attr", type=_key_value, action="append", metavar="KEY=VALUE",
                   help="extra attribute stored in the file (repeatable), e.g. ensemble=mono3d: the "
                        "validation and the figures group structure datasets by their ensemble")
    p.set_defaults(func=cmd_structure)
