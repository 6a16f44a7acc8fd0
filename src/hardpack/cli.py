"""The ``hardpack`` command line: one subcommand per step of the pipeline.

Core subcommands live here (``init``, ``info``, ``combine``); each study subpackage adds its own
through a ``register(subparsers)`` function in ``hardpack.<subpackage>.cli``.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys

import numpy as np

from hardpack import __version__
from hardpack.errors import InvalidInputError
from hardpack.process import job_process

#: the subcommands registered by this module itself (no other module is imported for them)
CORE_SUBCOMMANDS = ("init", "lattice", "laminate", "info", "combine")
#: the module that registers each subcommand beyond the core ones (its ``register(subparsers)``);
#: a command line imports only its own command's module, which keeps a job's start-up short
SUBCOMMANDS: dict[str, str] = {
    "compress": "hardpack.md.cli", "eos": "hardpack.md.cli", "crystal-search": "hardpack.md.cli",
    "poly-jam": "hardpack.eos.cli", "poly-fluid": "hardpack.eos.cli", "poly-summary": "hardpack.eos.cli",
    "poly-equivalents": "hardpack.eos.cli",
    "hgrid-cost": "hardpack.hgrid.cli",
    "slp": "hardpack.slp.cli", "slp-dilute": "hardpack.slp.cli",
    "validate": "hardpack.validation.cli",
    "structure": "hardpack.structure.cli",
    "verify": "hardpack.jamming.cli",
    "bcmd": "hardpack.freeenergy.cli", "bcmd-simplex": "hardpack.freeenergy.cli",
    "bcmd-ladder": "hardpack.freeenergy.cli", "bcmd-ellipse": "hardpack.freeenergy.cli",
    "ellipse-lattice": "hardpack.freeenergy.cli", "bcmd-ellipse-ladder": "hardpack.freeenergy.cli",
    "glass-crystal": "hardpack.glass.cli",
    "glass-separated-crystal": "hardpack.glass.cli", "glass-eos": "hardpack.glass.cli",
    "glass-entropy": "hardpack.glass.cli",
    "glass-freezing": "hardpack.glass.cli", "glass-relaxed": "hardpack.glass.cli",
    "glass-labels": "hardpack.glass.cli",
    "glass-labelled-crystal": "hardpack.glass.cli", "glass-microsegregated": "hardpack.glass.cli",
    "glass-microsegregated-summary": "hardpack.glass.cli",
    "glass-soc": "hardpack.glass.cli", "glass-soc-summary": "hardpack.glass.cli",
}
#: every module of :data:`SUBCOMMANDS`, in the order of ``hardpack --help``
SUBCOMMAND_MODULES: tuple[str, ...] = tuple(dict.fromkeys(SUBCOMMANDS.values()))


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


def add_checkpoint_options(p: argparse.ArgumentParser, checkpoint_help: str) -> None:
    """Add ``--checkpoint`` and ``--checkpoint-interval`` (seconds, default 300) to a
    subcommand's parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    checkpoint_help : str
        Help text of ``--checkpoint``.
    """
    p.add_argument("--checkpoint", help=checkpoint_help)
    p.add_argument("--checkpoint-interval", type=float, default=300.0,
                   help="seconds between checkpoints (default 300)")


def cmd_init(args) -> int:
    """Random sequential addition start configuration, written as a packing netCDF.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack init``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.distributions import from_spec
    from hardpack.initial import random_ellipsoid_packing, random_packing
    from hardpack.io import save_packing

    dist = from_spec(args.distribution)
    attrs = dict(args.attr or [])
    config = {"n": args.n, "d": args.d, "phi": args.phi, "distribution": args.distribution, "seed": args.seed}
    if args.wall_axes is not None and args.boundary != "hard_walls":
        raise InvalidInputError(f"--wall-axes is for --boundary hard_walls only, got --boundary {args.boundary}")
    if args.semiaxes is None:
        packing = random_packing(args.n, args.d, dist, args.phi, args.seed, boundary=args.boundary,
                                 wall_axes=args.wall_axes)
        if args.boundary != "periodic":
            config["boundary"] = args.boundary
            if args.wall_axes is not None:
                config["wall_axes"] = list(args.wall_axes)
    else:
        if len(args.semiaxes) != args.d:
            raise InvalidInputError(f"--semiaxes needs d = {args.d} numbers, one per body axis; got {args.semiaxes}")
        sizes = dist.sample(args.n, np.random.default_rng(args.seed))
        semiaxes = np.outer(sizes / sizes.min(), args.semiaxes)  # the smallest particle has --semiaxes
        packing = random_ellipsoid_packing(args.n, semiaxes, args.phi, args.seed, boundary=args.boundary,
                                           wall_axes=args.wall_axes)
        if args.boundary != "periodic":
            config["boundary"] = args.boundary
            if args.wall_axes is not None:
                config["wall_axes"] = list(args.wall_axes)
        attrs["semiaxes"] = list(args.semiaxes)
        config["semiaxes"] = list(args.semiaxes)
    attrs.update(
        seed=args.seed, distribution=args.distribution["kind"],
        distribution_params=args.distribution, init_phi=args.phi, protocol="rsa",
    )
    save_packing(packing, args.out, attrs=attrs, config=config)
    logging.info("wrote %s: %r", args.out, packing)
    return 0


def cmd_info(args) -> int:
    """Summary of a hardpack netCDF file: N, d, phi, particle shapes, boundary and provenance.

    A diagnostic: it also reads packings whose particles overlap, and reports the overlaps.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack info``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import load_dataset

    ds = load_dataset(args.file)
    kind = ds.attrs.get("hardpack_kind", "unknown")
    print(f"{args.file}: hardpack {kind}")
    if kind == "packing":
        from hardpack.io import dataset_to_packing

        p = dataset_to_packing(ds, source=str(args.file), allow_overlap=True)
        print(f"  N = {p.n_particles}, d = {p.dim}, phi = {p.phi:.10g}")
        if p.shape.kind == "sphere":
            r = p.radii
            print(f"  radii: min {r.min():.6g}, max {r.max():.6g}, mean {r.mean():.6g}, "
                  f"ratio {r.max() / r.min():.4g}")
        else:
            a = p.shape.semiaxes
            aspect = a.max(axis=1) / a.min(axis=1)
            print(f"  {p.shape.name}: semiaxes min {a.min():.6g}, max {a.max():.6g}; aspect ratio "
                  f"min {aspect.min():.6g}, max {aspect.max():.6g}")
        print(f"  boundary: {p.boundary}")
        region = "container volume" if p.boundary.kind == "spherical_container" else "cell volume"
        print(f"  {region} {p.volume:.6g}, orthorhombic: {p.is_orthorhombic}")
        diagnosis = " (shown for diagnosis: every other command refuses an overlapping packing)"
        try:
            report = p.overlap_report()
            print(f"  overlaps: {report}{diagnosis if report.n_overlapping else ''}")
            if p.boundary.kind != "periodic":
                walls = p.containment_report()
                print(f"  walls: {walls}{diagnosis if walls.n_outside else ''}")
        except NotImplementedError as exc:
            print(f"  overlaps: undecided ({exc})")
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
    """A crystal packing (spheres of radius 1/2 at contact), e.g. the FCC input of BCMD.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack lattice``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.geometry.lattices import lattice_packing
    from hardpack.io import save_packing

    packing = lattice_packing(args.name, args.reps)
    save_packing(packing, args.out, attrs={"lattice_name": args.name, "reps": args.reps, "protocol": "lattice"})
    logging.info("wrote %s: %r", args.out, packing)
    return 0


def cmd_laminate(args) -> int:
    """The laminate crystals of spheroids vs aspect ratio (Donev 2006, Sec. 8.2, Fig. 8.2).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack laminate``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.geometry.ellipsoid_crystals import DENSEST_ALPHA, laminate_family
    from hardpack.io import write_dataset

    if not (np.isfinite(args.alpha_max) and args.alpha_max >= 1):
        raise InvalidInputError(f"--alpha-max must be a finite number >= 1, got {args.alpha_max}")
    if not (np.isfinite(args.alpha_step) and args.alpha_step > 0):
        raise InvalidInputError(f"--alpha-step must be a positive number, got {args.alpha_step}")
    count = int(np.floor((args.alpha_max - 1) / args.alpha_step + 1e-9)) + 1
    alphas = 1 + args.alpha_step * np.arange(count)
    alphas = np.unique(np.round(np.concatenate([alphas, [args.alpha_max]]), 12))
    if args.alpha_max >= DENSEST_ALPHA:
        alphas = np.unique(np.concatenate([alphas[~np.isclose(alphas, DENSEST_ALPHA, rtol=0, atol=1e-9)],
                                           [DENSEST_ALPHA]]))
    family = laminate_family(alphas)
    write_dataset(family, args.out, attrs={"protocol": "laminate", "alpha_max": args.alpha_max,
                                           "alpha_step": args.alpha_step})
    logging.info("wrote %s: %d aspect ratios, densest phi = %.6f", args.out, alphas.size,
                 float(family["phi_densest"].max()))
    return 0


def cmd_combine(args) -> int:
    """Combine per-seed packings into one ensemble Dataset indexed by protocol parameters.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack combine``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import combine_ensemble, write_dataset

    ds = combine_ensemble(args.files, index=tuple(args.index), variables=tuple(args.variable or ()))
    write_dataset(ds, args.out, attrs=dict(args.attr or []))
    logging.info("wrote %s (%d samples)", args.out, ds.sizes["sample"])
    return 0


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``hardpack`` parser: the core subcommands and those each module of
    :data:`SUBCOMMAND_MODULES` registers.

    Parameters
    ----------
    command : str, optional
        A subcommand: only the core subcommands (:data:`CORE_SUBCOMMANDS`) and the module of
        ``command`` in :data:`SUBCOMMANDS` are imported and registered, so that a command does
        not pay for the imports of all the others. By default, or for any other name, every
        module is (``hardpack --help`` lists them all, and argparse's error for an unknown
        command names every choice).

    Returns
    -------
    argparse.ArgumentParser
        The parser; a parsed subcommand's handler is ``args.func``.
    """
    parser = argparse.ArgumentParser(prog="hardpack", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"hardpack {__version__}")
    parser.add_argument("-q", "--quiet", action="store_true", help="only print warnings and errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("init", help=cmd_init.__doc__.split("\n\n")[0])
    p.add_argument("--n", type=int, required=True, help="number of particles")
    p.add_argument("--d", type=int, required=True, help="dimension (2..6 and beyond)")
    p.add_argument("--phi", type=float, required=True, help="initial volume fraction (below RSA saturation)")
    p.add_argument("--distribution", type=_json_arg, default={"kind": "monodisperse"},
                   help='size distribution as JSON, e.g. \'{"kind": "uniform_volume", "omega": 4}\'')
    p.add_argument("--semiaxes", type=float, nargs="+",
                   help="ellipses (d = 2) or ellipsoids (d = 3) instead of spheres: the body-frame "
                        "semiaxes of the smallest particle, the others scaled by the size distribution; "
                        "random orientations")
    p.add_argument("--boundary", choices=("periodic", "hard_walls", "spherical_container"), default="periodic",
                   help="periodic cube (default); hard flat walls at 0 and L on --wall-axes (all by default); "
                        "or a hard spherical container whose volume gives --phi (Donev 2006, Ch. 7); ellipsoid "
                        "starts with walls or a container are dilute starts of bounding spheres")
    p.add_argument("--wall-axes", type=int, nargs="+", metavar="AXIS",
                   help="with --boundary hard_walls: the walled axes (0 = x, 1 = y, ...), periodic along the others")
    p.add_argument("--seed", type=int, required=True, help="random seed")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--attr", type=_key_value, action="append", metavar="KEY=VALUE",
                   help="extra attribute stored in the file (repeatable), e.g. ensemble=mono3d")
    p.set_defaults(func=cmd_init)

    p = sub.add_parser("lattice", help=cmd_lattice.__doc__.split("\n\n")[0])
    p.add_argument("--name", required=True,
                   help="fcc, hcp, bcc, sc, diamond, triangular, square, honeycomb, kagome, D<d>, hypercubic<d>")
    p.add_argument("--reps", type=int, nargs="+", default=[1], help="unit cells along each lattice vector")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_lattice)

    p = sub.add_parser("laminate", help=cmd_laminate.__doc__.split("\n\n")[0])
    p.add_argument("--alpha-max", type=float, default=3.0, help="largest aspect ratio, >= 1 (default 3)")
    p.add_argument("--alpha-step", type=float, default=0.05, help="step in alpha from 1 (default 0.05)")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_laminate)

    p = sub.add_parser("info", help=cmd_info.__doc__.split("\n\n")[0])
    p.add_argument("file", help="a netCDF file written by hardpack")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("combine", help=cmd_combine.__doc__.split("\n\n")[0])
    p.add_argument("files", nargs="+", help="packing files")
    p.add_argument("--index", nargs="+", default=["seed"], help="attributes indexing the samples")
    p.add_argument("--variable", action="append", help="extra numeric attribute to tabulate")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--attr", type=_key_value, action="append", metavar="KEY=VALUE")
    p.set_defaults(func=cmd_combine)

    if command in CORE_SUBCOMMANDS:
        modules = ()
    elif command in SUBCOMMANDS:
        modules = (SUBCOMMANDS[command],)
    else:
        modules = SUBCOMMAND_MODULES
    for module_name in modules:
        module = __import__(module_name, fromlist=["register"])
        module.register(sub)
    return parser


#: argparse destinations that name files a command writes; checked before the command runs
OUTPUT_OPTIONS = ("out", "timeseries", "history", "checkpoint", "out_nc", "out_md")
#: seeds are stored as 64-bit signed netCDF attributes
MAX_SEED = 2**63 - 1


def check_arguments(args) -> None:
    """Refuse, before any work, a seed out of range and output (or checkpoint) paths that cannot be
    written (:func:`hardpack.io.atomic.check_writable`), so that a long run never fails at its end.

    Parameters
    ----------
    args : argparse.Namespace
        A parsed subcommand; its ``seed`` and the destinations in :data:`OUTPUT_OPTIONS` are
        checked where present.

    Raises
    ------
    InvalidInputError
        If the seed is outside 0..2**63 - 1 or an output path cannot be written.
    """
    from hardpack.io.atomic import check_writable

    seed = getattr(args, "seed", None)
    if seed is not None and not 0 <= seed <= MAX_SEED:
        raise InvalidInputError(f"--seed must be an integer from 0 to 2**63 - 1, got {seed}")
    for dest in OUTPUT_OPTIONS:
        value = getattr(args, dest, None)
        for path in ([] if value is None else value if isinstance(value, list) else [value]):
            check_writable(path, "--" + dest.replace("_", "-"))


def run_command(args) -> int:
    """Run a parsed subcommand with the command line's error handling.

    Refused input (:class:`InvalidInputError`) and files that cannot be written (``OSError``) end
    in one line ``hardpack <command>: error: ...`` and exit status 2; SIGINT and SIGTERM end in
    ``hardpack <command>: interrupted: ...`` (after long runs wrote their checkpoint,
    :mod:`hardpack.io.interrupt`) and status 130 or 143; a closed standard output (``hardpack info
    FILE | head -1``) ends quietly with status 141 (128 + SIGPIPE), like other Unix tools.

    Parameters
    ----------
    args : argparse.Namespace
        A parsed subcommand (:func:`build_parser`), its handler in ``args.func``.

    Returns
    -------
    int
        Exit status: the handler's, or 2, 130, 143 or 141 as above.
    """
    from hardpack.io import interrupt

    prefix = f"hardpack {args.command}"
    try:
        check_arguments(args)
        with interrupt.installed():
            status = args.func(args)
            sys.stdout.flush()
        return status
    except InvalidInputError as exc:
        print(f"{prefix}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:
        where = f": {exc.filename}" if exc.filename else ""
        print(f"{prefix}: error: {exc.strerror or exc}{where}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        text = str(exc) or "stopped by SIGINT"
        checkpoint = getattr(args, "checkpoint", None)
        if checkpoint and "checkpoint" not in text:  # stopped at once, not by a polling run
            text += (f"; a checkpoint written before is kept in {checkpoint}: start the same command "
                     "again to resume from it")
        print(f"{prefix}: interrupted: {text}", file=sys.stderr)
        return getattr(exc, "exit_code", 130)


def main(argv=None) -> int:
    """The ``hardpack`` command: parse, set up logging (``-q``: warnings only) and run.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; default the process's command line.

    Returns
    -------
    int
        Exit status (:func:`run_command`).
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    command = next((word for word in argv if not word.startswith("-")), None)
    args = build_parser(command).parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING if args.quiet else logging.INFO,
        format="%(asctime)s %(name)s: %(message)s", datefmt="%H:%M:%S",
    )
    return run_command(args)


def console_main() -> None:
    """The ``hardpack`` console script: :func:`main` in a process of its own (a pipeline job),
    set up by :func:`hardpack.process.job_process` (the garbage collector tuned for a process that
    ends after one command). :func:`main` itself, which tests and other programs call in their
    own process, leaves the collector alone.
    """
    job_process()
    sys.exit(main())


if __name__ == "__main__":
    console_main()
