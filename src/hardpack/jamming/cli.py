"""``hardpack verify PACKING.nc --out VERDICT.nc``: jamming verdict of a stored packing.

Ellipse and ellipsoid packings go to :func:`hardpack.jamming.second_order.verify_ellipsoids`
(first- and second-order tests, contacts within mu - 1 <= delta, default 1e-9, or ``--delta gaps``
from the gap distribution). Sphere packings:
prints :meth:`JammingResult.summary` and writes :meth:`JammingResult.to_dataset` with
:func:`hardpack.io.write_dataset` (provenance attributes, atomic write). The generator's
reduced pressure, when the packing file carries one (attribute ``pressure``,
``reduced_pressure`` or ``final_pressure``), is compared with the free-volume pressure from the
contact forces.
"""

from __future__ import annotations

import math

from hardpack.jamming.result import CATEGORIES
from hardpack.jamming.verify import DEFAULT_DELTA, METHODS, SEQUENTIAL_DELTA, verify

#: attributes holding the generator's reduced pressure PV/(NkT); hardpack.md.compress stores it as "Z"
PRESSURE_ATTRS = ("reduced_pressure", "pressure", "final_pressure", "Z")


def register(subparsers) -> None:
    """Add the subcommand ``verify`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    p = subparsers.add_parser(
        "verify",
        help="LP jamming tests (local/collective/strict), rattlers and contact forces of a packing.",
        description=__doc__.splitlines()[0],
    )
    p.add_argument("packing", help="packing netCDF file (hardpack.io.save_packing)")
    p.add_argument("--out", required=True, help="output netCDF file for the verdict")
    p.add_argument("--delta", type=_delta, default=None,
                   help=f"relative gap tolerance of the contact list, 0 < delta < 1 (default "
                        f"{DEFAULT_DELTA:g} for the ideal method, {SEQUENTIAL_DELTA:g} for the "
                        "sequential one, whose contacts for Z and forces stay at "
                        f"{DEFAULT_DELTA:g}); ellipses and ellipsoids: 'gaps' reads it off the "
                        "gap distribution (packings compressed to a high pressure)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random loads (default 0)")
    p.add_argument("--method", choices=METHODS, default="ideal",
                   help="ideal: Algorithm 13 (default); sequential: Algorithm 14")
    p.add_argument("--tests", nargs="+", choices=CATEGORIES, default=list(CATEGORIES),
                   help="tests to run (default: all three)")
    p.add_argument("--dr-large", type=float, default=None,
                   help="displacement counted as unjamming (default delta x mean diameter)")
    p.add_argument("--threshold", type=float, default=1e-3,
                   help="sequential method: mean displacement / D above which 'not jammed'")
    p.add_argument("--checkpoint", default=None,
                   help="sequential method: checkpoint file written after every loading sequence; "
                        "a killed run started again with the same arguments resumes from it "
                        "(removed at the end)")
    p.add_argument("--workers", type=int, default=1,
                   help="sequential method: loading sequences run at once, one process each "
                        "(default 1; the result does not depend on it)")
    p.add_argument("--attr", type=_key_value, action="append", metavar="KEY=VALUE",
                   help="extra attribute stored in the verdict (repeatable), e.g. alpha=1.5")
    p.add_argument("--refine", action="store_true",
                   help="ellipses and ellipsoids near their jamming point (LS packings): test the "
                        "jamming point of the contacts, found by Newton's method, when it converges "
                        "with no overlap, if need be after an SLP ascent of the size; certify a "
                        "second-order flexible verdict there by an explicit denser packing "
                        "(periodic cells, flat walls and spherical containers; the ascent periodic "
                        "cells only: hardpack.jamming.refine, hardpack.jamming.ascent)")
    p.add_argument("--ascent-max-particles", type=int, default=None, metavar="N",
                   help="with --refine: the largest packing for which the SLP ascent runs (default 400; an "
                        "ascent took 6-60 CPU-min at N = 640-800 and a certificate takes up to six)")
    p.set_defaults(func=cmd_verify)


def _key_value(text: str):
    from hardpack.cli import _key_value as parse

    return parse(text)


def _delta(text: str):
    """--delta: a number, or 'gaps' (ellipsoids)."""
    return text if text == "gaps" else float(text)


def _write_verdict(result, out, args) -> int:
    """Write the verdict dataset ``out`` with the --attr attributes and print its summary."""
    from hardpack.io import write_dataset

    out.attrs.update(dict(args.attr or []))
    write_dataset(out, args.out, seed=args.seed)
    print(result.summary())
    print(f"written {args.out}")
    return 0


def _verify_ellipsoids(packing, args) -> int:
    """Ellipses and ellipsoids: the first- and second-order tests of
    :func:`hardpack.jamming.second_order.verify_ellipsoids` (the sphere options do not apply)."""
    from hardpack.errors import InvalidInputError
    from hardpack.jamming.refine import verify_at_jamming_point
    from hardpack.jamming.second_order import verify_ellipsoids

    if args.ascent_max_particles is not None and not args.refine:
        raise InvalidInputError("--ascent-max-particles applies with --refine only")
    if args.refine:
        limit = {} if args.ascent_max_particles is None else {"ascent_max_particles": args.ascent_max_particles}
        result = verify_at_jamming_point(packing, delta=args.delta, seed=args.seed, **limit)
    else:
        result = verify_ellipsoids(packing, delta=args.delta, seed=args.seed)
    out = result.to_dataset()
    out.attrs["source"] = str(args.packing)
    return _write_verdict(result, out, args)


def cmd_verify(args) -> int:
    """Jamming verdict of a stored packing (module docstring): writes the verdict dataset to
    ``args.out`` and prints its summary.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack verify``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import dataset_to_packing, load_dataset

    ds = load_dataset(args.packing, kind="packing")
    if ds.attrs.get("shape_kind") == "ellipsoid":
        # verify_ellipsoids checks the overlaps itself (with the Perram-Wertheim function)
        return _verify_ellipsoids(dataset_to_packing(ds, source=str(args.packing), allow_overlap=True), args)
    ellipsoid_only = [name for name, given in (("--delta gaps", args.delta == "gaps"), ("--refine", args.refine),
                                               ("--ascent-max-particles", args.ascent_max_particles is not None))
                      if given]
    if ellipsoid_only:
        from hardpack.errors import InvalidInputError

        raise InvalidInputError(f"{ellipsoid_only[0]} is for ellipse and ellipsoid packings; sphere packings take "
                                "none of --delta gaps, --refine, --ascent-max-particles (--delta a number)")
    packing = dataset_to_packing(ds, source=str(args.packing))
    pressure = next((float(ds.attrs[k]) for k in PRESSURE_ATTRS if k in ds.attrs), None)
    if pressure is not None and not (math.isfinite(pressure) and pressure > 0):
        pressure = None  # e.g. a generator that stopped before measuring one
    result = verify(
        packing, delta=args.delta, tests=tuple(args.tests), seed=args.seed,
        method=args.method, dr_large=args.dr_large, threshold=args.threshold,
        md_pressure=pressure, checkpoint=args.checkpoint, workers=args.workers,
    )
    out = result.to_dataset()
    out.attrs["source"] = str(args.packing)
    if "md_contact_force" in ds and result.forces.exists:
        from hardpack.jamming.md_forces import compare_md_forces

        pairs = result.network.among(~result.rattler) & ~result.network.is_wall  # the MD records pairs
        cmp = compare_md_forces(result.network, result.forces.forces, pairs, ds)
        out.attrs.update(cmp.as_attrs())
        print(f"MD contact forces: LP virial / MD collisional pressure = {cmp.pressure_ratio:.4f}, "
              f"rms force difference {cmp.rms_relative:.3g} of the mean ({cmp.n_matched} of "
              f"{cmp.n_lp_contacts} contacts matched)")
    return _write_verdict(result, out, args)
