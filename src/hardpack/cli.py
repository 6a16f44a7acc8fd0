"""The ``hardpack`` command line: one subcommand per step of the pipeline.

Core subcommands live here (``init``, ``info``, ``combine``); each study subpackage adds its own
through a ``register(subparsers)`` function in ``hardpack.<subpackage>.cli``.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys

import numpy as np

from hardpack import __version__
from hardpack.errors import InvalidInputError

SUBCOMMAND_MODULES: tuple[str, ...] = ("hardpack.md.cli", "hardpack.eos.cli", "hardpack.hgrid.cli", "hardpack.slp.cli", "hardpack.validation.cli", "hardpack.structure.cli", "hardpack.jamming.cli", "hardpack.freeenergy.cli")


def _json_arg(text: str):
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise argparse.ArgumentTypeError(f"not valid JSON ({exc}): {text!r}") from None


def _key_value(text: str):
    if "=" not in text:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    key, value = text.split("=", 1)
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        return key, value


def cmd_init(args) -> int:
    """Random sequential addition start configuration, written as a packing netCDF."""
    from hardpack.distributions import from_spec
    from hardpack.initial import random_packing
    from hardpack.io import save_packing

    dist = from_spec(args.distribution)
    packing = random_packing(args.n, args.d, dist, args.phi, args.seed)
    attrs = dict(args.attr or [])
    attrs.update(
        seed=args.seed, distribution=args.distribution["kind"],
        distribution_params=args.distribution, init_phi=args.phi, protocol="rsa",
    )
    config = {"n": args.n, "d": args.d, "phi": args.phi, "distribution": args.distribution, "seed": args.seed}
    save_packing(packing, args.out, attrs=attrs, config=config)
    logging.info("wrote %s: %r", args.out, packing)
    return 0


def cmd_info(args) -> int:
    """Summary of a hardpack netCDF file: N, d, phi, radii and provenance."""
    from hardpack.io import load_dataset

    ds = load_dataset(args.file)
    kind = ds.attrs.get("hardpack_kind", "unknown")
    print(f"{args.file}: hardpack {kind}")
    if kind == "packing":
        from hardpack.io import dataset_to_packing

        p = dataset_to_packing(ds, source=str(args.file), allow_overlap=True)
        r = p.radii
        print(f"  N = {p.n_particles}, d = {p.dim}, phi = {p.phi:.10g}")
        print(f"  radii: min {r.min():.6g}, max {r.max():.6g}, mean {r.mean():.6g}, "
              f"ratio {r.max() / r.min():.4g}")
        print(f"  cell volume {p.volume:.6g}, orthorhombic: {p.is_orthorhombic}")
        report = p.overlap_report()
        print(f"  overlaps: {report}")
    else:
        print("  " + ", ".join(f"{k}: {v}" for k, v in ds.sizes.items()))
        for name, var in ds.data_vars.items():
            print(f"  {name}{tuple(var.dims)}")
    print("  attributes:")
    for key, value in ds.attrs.items():
        if key in ("hardpack_kind",):
            continue
        text = value.tolist() if isinstance(value, np.ndarray) else value
        print(f"    {key}: {text}")
    return 0


def cmd_lattice(args) -> int:
    """A crystal packing (spheres of radius 1/2 at contact), e.g. the FCC input of BCMD."""
    from hardpack.geometry.lattices import lattice_packing
    from hardpack.io import save_packing

    packing = lattice_packing(args.name, args.reps)
    save_packing(packing, args.out, attrs={"lattice_name": args.name, "reps": args.reps, "protocol": "lattice"})
    logging.info("wrote %s: %r", args.out, packing)
    return 0


def cmd_combine(args) -> int:
    """Combine per-seed packings into one ensemble Dataset indexed by protocol parameters."""
    from hardpack.io import combine_ensemble, write_dataset

    ds = combine_ensemble(args.files, index=tuple(args.index), variables=tuple(args.variable or ()))
    write_dataset(ds, args.out, attrs=dict(args.attr or []))
    logging.info("wrote %s (%d samples)", args.out, ds.sizes["sample"])
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="hardpack", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"hardpack {__version__}")
    parser.add_argument("-q", "--quiet", action="store_true", help="only print warnings and errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("init", help=cmd_init.__doc__)
    p.add_argument("--n", type=int, required=True, help="number of particles")
    p.add_argument("--d", type=int, required=True, help="dimension (2..6 and beyond)")
    p.add_argument("--phi", type=float, required=True, help="initial volume fraction (below RSA saturation)")
    p.add_argument("--distribution", type=_json_arg, default={"kind": "monodisperse"},
                   help='size distribution as JSON, e.g. \'{"kind": "uniform_volume", "omega": 4}\'')
    p.add_argument("--seed", type=int, required=True, help="random seed")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--attr", type=_key_value, action="append", metavar="KEY=VALUE",
                   help="extra attribute stored in the file (repeatable), e.g. ensemble=mono3d")
    p.set_defaults(func=cmd_init)

    p = sub.add_parser("lattice", help=cmd_lattice.__doc__)
    p.add_argument("--name", required=True, help="fcc, hcp, bcc, sc, diamond, triangular, square, honeycomb, kagome, D<d>, hypercubic<d>")
    p.add_argument("--reps", type=int, nargs="+", default=[1], help="unit cells along each lattice vector")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_lattice)

    p = sub.add_parser("info", help=cmd_info.__doc__)
    p.add_argument("file", help="a netCDF file written by hardpack")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("combine", help=cmd_combine.__doc__)
    p.add_argument("files", nargs="+", help="packing files")
    p.add_argument("--index", nargs="+", default=["seed"], help="attributes indexing the samples")
    p.add_argument("--variable", action="append", help="extra numeric attribute to tabulate")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--attr", type=_key_value, action="append", metavar="KEY=VALUE")
    p.set_defaults(func=cmd_combine)

    for module_name in SUBCOMMAND_MODULES:
        module = __import__(module_name, fromlist=["register"])
        module.register(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING if args.quiet else logging.INFO,
        format="%(asctime)s %(name)s: %(message)s", datefmt="%H:%M:%S",
    )
    try:
        return args.func(args)
    except InvalidInputError as exc:
        print(f"hardpack {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
