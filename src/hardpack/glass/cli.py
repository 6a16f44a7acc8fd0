"""``hardpack glass-crystal``: the triangular start crystal of the monodisperse EOS;
``hardpack glass-eos``: binned EOS, fits (Eqs. 13.3-13.4) and free energies of one system from its
compression (and decompression) time series; ``hardpack glass-entropy``: s_c - s_mix of the SOC
glasses from the EOS summary and their BCMD results; ``hardpack glass-freezing``: phi_F by
chemical-potential matching (Eq. 13.2); ``hardpack glass-relaxed``: jamming densities of fast glasses
before and after relaxation (Fig. 13.8); ``hardpack glass-labels``: level-cut Matérn labels of the
micro-segregated packings and their window entropies (sec. 13.5); ``hardpack glass-labelled-crystal``:
the triangular crystal carrying one realisation of those labels; ``hardpack glass-soc``: compression of a
snapshot with every disk in a fixed cell (Fig. 13.9); ``hardpack glass-soc-summary``: phi_J of those SOC
solids before and after relaxation without cells. Donev 2006, ch. 13
(:mod:`hardpack.glass`).
"""

from __future__ import annotations

import logging
from collections import defaultdict

import numpy as np

from hardpack.errors import InvalidInputError

log = logging.getLogger(__name__)


def cmd_glass_crystal(args) -> int:
    """Monodisperse triangular crystal in an orthorhombic periodic box at a given phi.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-crystal``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.study import triangular_crystal
    from hardpack.io import save_packing

    packing = triangular_crystal(args.nx, args.ny, args.phi)
    save_packing(packing, args.out, attrs={"protocol": "triangular_crystal", "nx": args.nx, "ny": args.ny})
    log.info("wrote %s: %r", args.out, packing)
    return 0


def cmd_glass_separated_crystal(args) -> int:
    """Fully phase-separated binary crystal: a slab of small and a slab of large disks (Donev 2006, sec. 13.2.2.1).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-separated-crystal``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.study import phase_separated_crystal
    from hardpack.io import save_packing

    packing = phase_separated_crystal(args.columns, args.rows, args.kappa, args.phi)
    save_packing(packing, args.out, attrs={"protocol": "phase_separated_crystal", "kappa": args.kappa})
    log.info("wrote %s: %r", args.out, packing)
    return 0


def _branch_name(rate: float) -> str:
    return "decompression" if rate < 0 else f"{rate:g}"


def cmd_glass_eos(args) -> int:
    """Binned EOS of a system's compressions (one branch per growth rate) and decompression.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-eos``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.study import continued_run, eos_dataset
    from hardpack.glass.thermo import second_virial_slope
    from hardpack.io import load_dataset, write_dataset

    runs = defaultdict(lambda: defaultdict(list))
    n = d = None
    for path in args.files:
        ts = load_dataset(path, kind="md_timeseries")
        rate, seed = float(ts.attrs["growth_rate"]), int(ts.attrs["seed"])
        runs[_branch_name(rate)][seed].append(ts)
        n, d = int(ts.attrs["N"]), int(ts.attrs["d"])
    starts = {}
    for rate, parent in args.continues or []:
        name, pname = _branch_name(rate), _branch_name(parent)
        if name not in runs or pname not in runs:
            raise InvalidInputError(f"--continues {rate:g} {parent:g}: no time series of growth rate "
                                    f"{rate if name not in runs else parent:g} among the files")
        for seed, series in runs[name].items():
            if seed not in runs[pname]:
                raise InvalidInputError(f"--continues {rate:g} {parent:g}: seed {seed} has no time series "
                                        f"at growth rate {parent:g}")
            runs[name][seed], starts[name] = continued_run(series, runs[pname][seed])
    branches = {}
    for name in sorted(runs, key=lambda s: (s == "decompression", -float(s) if s != "decompression" else 0)):
        branches[name] = [sorted(series, key=lambda ts: float(ts["phi"].values[0]), reverse=name == "decompression")
                          for _, series in sorted(runs[name].items())]
    if not np.isclose(args.bin_width * round((args.phi_max - args.phi_min) / args.bin_width),
                      args.phi_max - args.phi_min):
        raise InvalidInputError("--phi-max - --phi-min must be a whole number of --bin-width")
    edges = np.linspace(args.phi_min, args.phi_max, round((args.phi_max - args.phi_min) / args.bin_width) + 1)
    slope0 = second_virial_slope(d, args.kappa, args.x_large)
    ds = eos_dataset(branches, edges, d=d, slope0=slope0, liquid_range=tuple(args.liquid_range),
                     glass_range=tuple(args.glass_range), starts=starts,
                     attrs={"system": args.system, "kappa": args.kappa, "x_large": args.x_large, "N": n,
                            "continued_branches": "; ".join(f"{_branch_name(r)} from {_branch_name(p)}"
                                                            for r, p in args.continues or [])})
    write_dataset(ds, args.out)
    c, ce = ds["cubic"].values, ds["cubic_err"].values
    log.info("%s: branches %s; Eq. 13.3 fit up to phi = %.4f: %s +- %s; alpha %s", args.system, list(branches),
             ds.attrs["liquid_fit_max"], np.round(c, 4).tolist(), np.round(ce, 4).tolist(),
             np.round(ds["alpha"].values, 4).tolist())
    return 0


def cmd_glass_entropy(args) -> int:
    """s_c - s_mix of the SOC glasses (Donev 2006, Eq. 13.5, Fig. 13.12).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-entropy``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.study import entropy_dataset
    from hardpack.io import dataset_to_packing, load_dataset, write_dataset
    from hardpack.structure.order import coordination_defects

    eos = load_dataset(args.eos, kind="glass_eos")
    bcmd = []
    for path in args.bcmd:
        ds = load_dataset(path, kind="bcmd")
        snapshot = load_dataset(ds.attrs["source"], kind="packing")
        snap = snapshot.attrs
        defects = coordination_defects(dataset_to_packing(snapshot, ds.attrs["source"]))
        # the snapshot's density as targeted (a stage reaches its target exactly unless it jammed)
        ds.attrs.update(phi0=round(float(snap["phi"]), 4), growth_rate=float(snap["growth_rate"]),
                        seed=int(snap["seed"]), coordination_defects=defects)
        bcmd.append(ds)
    ds = entropy_dataset(eos, bcmd, x_large=float(eos.attrs["x_large"]), attrs={"system": eos.attrs["system"]})
    write_dataset(ds, args.out)
    for i in range(ds.sizes["sample"]):
        r = ds.isel(sample=i)
        log.info("phi0 = %.3f seed %d: Delta f_g = %.4f, Delta f_L = %.4f, s_c - s_mix = %.4f +- %.4f, "
                 "%.2f %% of the disks without six neighbours",
                 float(r["phi0"]), int(r["seed"]), float(r["glass_excess"]), float(r["liquid_excess"]),
                 float(r["sc_minus_smix"]), float(r["sc_minus_smix_err"]), 100 * float(r["coordination_defects"]))
    return 0


def cmd_glass_freezing(args) -> int:
    """Freezing density of the mixture and its large-disk precipitate (Donev 2006, Eq. 13.2).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-freezing``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.study import freezing_dataset
    from hardpack.io import load_dataset, write_dataset

    if (args.plus is None) != (args.minus is None):
        raise InvalidInputError("give both --plus and --minus (the neighbouring compositions) or neither")
    eos = {k: None if p is None else load_dataset(p, kind="glass_eos")
           for k, p in (("mono", args.mono), ("mixture", args.mixture), ("plus", args.plus), ("minus", args.minus))}
    ds = freezing_dataset(eos["mono"], eos["mixture"], eos["plus"], eos["minus"], kappa=args.kappa,
                          x_large=args.x_large, dx=args.dx, phi_join=args.phi_join)
    write_dataset(ds, args.out)
    log.info("freezing: %s; phi_F = %.4f, precipitate phi = %.4f", ds.attrs["status"],
             float(ds["phi_freeze"]), float(ds["phi_precipitate"]))
    return 0


def cmd_glass_relaxed(args) -> int:
    """Jamming densities of fast glasses before and after relaxation (Donev 2006, Fig. 13.8).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-relaxed``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.study import relaxed_dataset
    from hardpack.io import load_dataset, write_dataset

    ds = relaxed_dataset([load_dataset(p, kind="packing") for p in args.fast],
                         [load_dataset(p, kind="packing") for p in args.jammed], relax_collisions=args.relax_collisions)
    write_dataset(ds, args.out)
    for rate in np.unique(ds["rate"].values):
        sel = ds["rate"].values == rate
        log.info("Gamma = %g: phi_J %.4f before, %.4f after relaxation (%d runs)", rate,
                 ds["phi_J_fast"].values[sel].mean(), ds["phi_J"].values[sel].mean(), sel.sum())
    return 0


def cmd_glass_labels(args) -> int:
    """Level-cut Matérn GRF labels and their window entropies s_{n,m} (Donev 2006, sec. 13.5).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-labels``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.segregated import check_window, count_a, label_study, matern
    from hardpack.io import write_dataset

    matern(0.0, args.R, args.nu)  # refuses bad R / nu before anything runs
    count_a(1, args.fraction_a)
    check_window(args.shape, args.window)
    if args.realisations < 1:
        raise InvalidInputError(f"--realisations must be >= 1, got {args.realisations}")
    ds = label_study(args.shape, args.R, args.nu, args.fraction_a, args.seed, args.realisations, args.window)
    config = {"shape": list(args.shape), "R": args.R, "nu": args.nu, "fraction_a": args.fraction_a,
              "realisations": args.realisations, "window": list(args.window)}
    write_dataset(ds, args.out, config=config, seed=args.seed)
    s = ds["entropy_per_site"].values
    log.info("R = %g, nu = %g: s_{n,n} = %s (s_mix = %.4f); %d windows; clipped eigenvalue weight %.3g",
             args.R, args.nu, np.round(np.diag(s), 4).tolist(), ds.attrs["s_mix"], ds.attrs["n_windows"],
             ds.attrs["clipped_weight"])
    return 0


def cmd_glass_labelled_crystal(args) -> int:
    """Triangular crystal of equal disks carrying one realisation of glass-labels (species 0 = A, 1 = B).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-labelled-crystal``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.segregated import labelled_crystal
    from hardpack.io import load_dataset, save_packing

    ds = load_dataset(args.labels, kind="glass_labels")
    k = ds.sizes["realisation"]
    if not 0 <= args.realisation < k:
        raise InvalidInputError(f"--realisation must be in 0..{k - 1} ({args.labels} holds {k}), "
                                f"got {args.realisation}")
    packing = labelled_crystal(ds["labels"].values[args.realisation], args.phi)
    attrs = {"protocol": "labelled_triangular_crystal", "labels_source": str(args.labels),
             "realisation": args.realisation, **{key: ds.attrs[key] for key in ("R", "nu", "fraction_a", "seed")}}
    save_packing(packing, args.out, attrs=attrs)
    log.info("wrote %s: %r", args.out, packing)
    return 0


def cmd_glass_microsegregated(args) -> int:
    """Micro-segregated packing: B growth at constant pressure, then LS to jamming (Donev 2006, sec. 13.5).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-microsegregated``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.microsegregated import microsegregated_packing
    from hardpack.io import load_dataset, write_dataset
    from hardpack.io.atomic import check_writable

    for path in (args.out, args.growth_timeseries, args.timeseries):
        if path is not None:
            check_writable(path)
    labels = load_dataset(args.labels, kind="glass_labels")
    result, growth_ts = microsegregated_packing(
        labels, args.realisation, ensemble=args.ensemble, ratio=args.kappa, pressure=args.pressure,
        growth_rate=args.growth_rate,
        compress_rate=args.compress_rate, max_pressure=args.max_pressure, seed=args.seed, cell_step=args.cell_step)
    config = {k: getattr(args, k) for k in ("labels", "realisation", "ensemble", "kappa", "pressure", "growth_rate",
                                            "compress_rate", "max_pressure", "cell_step")}
    result.save(args.out, args.timeseries, config=config)
    if args.growth_timeseries is not None:
        write_dataset(growth_ts, args.growth_timeseries, config=config, seed=args.seed)
    st = result.stats
    log.info("R = %g, nu = %g: phi_J = %.5f, s_c = %.4f; growth to kappa = %.6g at p = %g: mean pressure error "
             "%.3g; %d + %d collisions", st["R"], st["nu"], st["phi_J"], st["s_c"], st["growth_ratio"],
             st["growth_pressure"], st["growth_pressure_error_mean"], st["growth_collisions"], st["collisions"])
    return 0


def cmd_glass_soc(args) -> int:
    """SOC compression: each disk in a fixed cell around its start, grown to near jamming (Donev 2006, Fig. 13.9).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-soc``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.soc import compress_in_cells
    from hardpack.io import load_packing, save_packing, write_dataset
    from hardpack.io.atomic import check_writable

    for path in (args.out, args.timeseries):
        check_writable(path)
    result = compress_in_cells(load_packing(args.packing), dmu=args.dmu, growth_rate=args.growth_rate,
                               max_pressure=args.max_pressure, seed=args.seed, window=args.window,
                               checkpoint=args.checkpoint)
    config = {"source": str(args.packing), "dmu": args.dmu, "growth_rate": args.growth_rate,
              "max_pressure": args.max_pressure, "window": args.window}
    ts = result.timeseries
    write_dataset(ts, args.timeseries, attrs={"source": str(args.packing)}, config=config, seed=args.seed)
    save_packing(result.packing, args.out, attrs={"protocol": "soc_compression", "source": str(args.packing),
                                                  "phi0": ts.attrs["phi0"], "Z": ts.attrs["Z_final"],
                                                  "phi_J_est": ts.attrs["phi_J_est"]}, config=config, seed=args.seed)
    log.info("phi0 = %.5f -> phi = %.6f at Z = %.4g (%s): phi_J ~ %.5f", ts.attrs["phi0"], ts.attrs["phi_final"],
             ts.attrs["Z_final"], result.stop, ts.attrs["phi_J_est"])
    return 0


def cmd_glass_soc_summary(args) -> int:
    """phi_J of SOC solids after their compression and after relaxation without cells (Donev 2006, Fig. 13.9).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-soc-summary``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.soc import soc_summary
    from hardpack.io import load_dataset, write_dataset

    ds = soc_summary([load_dataset(p, kind="soc_compression") for p in args.soc],
                     [load_dataset(p, kind="md_eos") for p in args.relaxed])
    write_dataset(ds, args.out)
    for p in ds["phi0"].values:
        row = ds.sel(phi0=p)
        log.info("phi0 = %.4g: phi_J %.4f in cells -> %.4f relaxed (mean over %d seeds)", p,
                 float(row["phi_J_soc"].mean()), float(row["phi_J_relaxed"].mean()), ds.sizes["seed"])
    return 0


def cmd_glass_microsegregated_summary(args) -> int:
    """phi_J and s_c per label ensemble of micro-segregated packings (Donev 2006, Figs. 13.16-13.17).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack glass-microsegregated-summary``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.glass.microsegregated import summary_dataset
    from hardpack.io import load_dataset, write_dataset

    ds = summary_dataset([load_dataset(p, kind="packing") for p in args.files])
    write_dataset(ds, args.out)
    for name in ds.ensemble.values:
        row = ds.sel(ensemble=name)
        log.info("%s: R = %g, nu = %g, s_c = %.4f, phi_J = %.5f +- %.5f (%d packings)", name, float(row.R),
                 float(row.nu), float(row.s_c), float(row.phi_J), float(row.phi_J_err), int(row.n_packings))
    return 0


def register(subparsers) -> None:
    """Add the subcommands ``glass-crystal``, ``glass-eos``, ``glass-entropy``, ``glass-freezing``, ``glass-relaxed``,
    ``glass-labels``, ``glass-labelled-crystal``, ``glass-microsegregated``,
    ``glass-microsegregated-summary``, ``glass-soc``, ``glass-soc-summary`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    p = subparsers.add_parser("glass-crystal", help=cmd_glass_crystal.__doc__.split("\n\n")[0])
    p.add_argument("--nx", type=int, required=True, help="rectangular 2-disk cells along x")
    p.add_argument("--ny", type=int, required=True, help="rectangular 2-disk cells along y")
    p.add_argument("--phi", type=float, required=True, help="volume fraction (< pi/sqrt(12))")
    p.add_argument("--out", required=True, help="packing netCDF")
    p.set_defaults(func=cmd_glass_crystal)

    p = subparsers.add_parser("glass-separated-crystal",
                              help=cmd_glass_separated_crystal.__doc__.split("\n\n")[0])
    p.add_argument("--columns", type=int, nargs=2, required=True, metavar=("A", "B"),
                   help="columns of the small-disk and the large-disk slab (their ratio is kappa: 7 k, 5 k)")
    p.add_argument("--rows", type=int, nargs=2, required=True, metavar=("A", "B"),
                   help="rows (even) of the two slabs (10 j, 7 j give one third large disks)")
    p.add_argument("--kappa", type=float, required=True, help="diameter ratio large / small")
    p.add_argument("--phi", type=float, required=True, help="overall volume fraction")
    p.add_argument("--out", required=True, help="packing netCDF")
    p.set_defaults(func=cmd_glass_separated_crystal)

    p = subparsers.add_parser("glass-eos", help=cmd_glass_eos.__doc__.split("\n\n")[0])
    p.add_argument("files", nargs="+", help="compression / decompression time series of one system")
    p.add_argument("--system", required=True, help="system name (stored)")
    p.add_argument("--kappa", type=float, default=1.0, help="diameter ratio (1: monodisperse)")
    p.add_argument("--x-large", type=float, default=0.0, help="number fraction of the large disks")
    p.add_argument("--bin-width", type=float, default=0.005, help="phi bin width (default 0.005)")
    p.add_argument("--phi-min", type=float, default=0.0, help="lowest bin edge (default 0)")
    p.add_argument("--phi-max", type=float, default=0.9, help="highest bin edge (default 0.9)")
    p.add_argument("--liquid-range", type=float, nargs=2, default=[0.70, 0.80],
                   help="phi range of the Eq. 13.3 cubic fit (default 0.70 0.80); the fit stops earlier where "
                        "the slowest compression and the next faster one separate (Donev 2006, sec. 13.3.1)")
    p.add_argument("--glass-range", type=float, nargs=2, default=[0.80, 0.84],
                   help="phi range of the Eq. 13.4 glass-branch fit (default 0.80 0.84)")
    p.add_argument("--continues", type=float, nargs=2, action="append", metavar=("RATE", "PARENT"),
                   help="the compression at RATE starts from a stage of the one at PARENT (same seeds): "
                        "its EOS integral runs along the parent's time series up to there (repeatable)")
    p.add_argument("--out", required=True, help="EOS summary netCDF")
    p.set_defaults(func=cmd_glass_eos)

    p = subparsers.add_parser("glass-entropy", help=cmd_glass_entropy.__doc__.split("\n\n")[0])
    p.add_argument("--eos", required=True, help="the system's glass-eos summary")
    p.add_argument("bcmd", nargs="+", help="BCMD results of the glass snapshots")
    p.add_argument("--out", required=True, help="entropy summary netCDF")
    p.set_defaults(func=cmd_glass_entropy)

    p = subparsers.add_parser("glass-freezing", help=cmd_glass_freezing.__doc__.split("\n\n")[0])
    p.add_argument("--mono", required=True, help="glass-eos summary of monodisperse disks (with a decompression)")
    p.add_argument("--mixture", required=True, help="glass-eos summary of the mixture")
    p.add_argument("--plus", help="glass-eos summary at x_A + dx (x_large - dx)")
    p.add_argument("--minus", help="glass-eos summary at x_A - dx (x_large + dx)")
    p.add_argument("--dx", type=float, default=0.05, help="composition step of --plus / --minus")
    p.add_argument("--kappa", type=float, required=True, help="diameter ratio")
    p.add_argument("--x-large", type=float, required=True, help="number fraction of the large disks")
    p.add_argument("--phi-join", type=float, default=0.70,
                   help="monodisperse EOS: compression below, decompression from here up (default 0.70)")
    p.add_argument("--out", required=True, help="freezing netCDF")
    p.set_defaults(func=cmd_glass_freezing)

    p = subparsers.add_parser("glass-relaxed", help=cmd_glass_relaxed.__doc__.split("\n\n")[0])
    p.add_argument("--fast", nargs="+", required=True, help="packings after the fast compressions")
    p.add_argument("--jammed", nargs="+", required=True, help="the same runs after relaxation and recompression")
    p.add_argument("--relax-collisions", type=float, required=True,
                   help="collisions per particle of the relaxation at fixed phi (recorded)")
    p.add_argument("--out", required=True, help="summary netCDF")
    p.set_defaults(func=cmd_glass_relaxed)

    p = subparsers.add_parser("glass-labels", help=cmd_glass_labels.__doc__.split("\n\n")[0])
    p.add_argument("--shape", type=int, nargs=2, default=[64, 64], metavar=("ROWS", "COLS"),
                   help="periodic lattice (default 64 64)")
    p.add_argument("--R", type=float, required=True, help="Matérn correlation length (> 0, lattice units)")
    p.add_argument("--nu", type=float, required=True, help="Matérn smoothness in (0, 1)")
    p.add_argument("--fraction-a", type=float, default=2 / 3, help="fraction of A (small) sites (default 2/3)")
    p.add_argument("--seed", type=int, required=True, help="seed of the realisations")
    p.add_argument("--realisations", type=int, default=1, help="independent fields pooled in the statistics")
    p.add_argument("--window", type=int, nargs=2, default=[4, 4], metavar=("N", "M"),
                   help="largest window for S_{n,m} and s_{n,m} (default 4 4)")
    p.add_argument("--out", required=True, help="labels netCDF")
    p.set_defaults(func=cmd_glass_labels)

    p = subparsers.add_parser("glass-labelled-crystal", help=cmd_glass_labelled_crystal.__doc__.split("\n\n")[0])
    p.add_argument("--labels", required=True, help="glass-labels netCDF")
    p.add_argument("--realisation", type=int, default=0, help="which realisation (default 0)")
    p.add_argument("--phi", type=float, required=True, help="volume fraction (< pi/sqrt(12))")
    p.add_argument("--out", required=True, help="packing netCDF")
    p.set_defaults(func=cmd_glass_labelled_crystal)

    p = subparsers.add_parser("glass-microsegregated", help=cmd_glass_microsegregated.__doc__.split("\n\n")[0])
    p.add_argument("--labels", required=True, help="glass-labels netCDF (its window entropy is s_c)")
    p.add_argument("--realisation", type=int, default=0, help="which label realisation (default 0)")
    p.add_argument("--ensemble", default="", help="name of the label ensemble (\"random\": the MRJ reference)")
    p.add_argument("--kappa", type=float, default=1.4, help="target diameter ratio (default 1.4)")
    p.add_argument("--pressure", type=float, default=100.0,
                   help="reduced pressure pV/(NkT) held during the growth (default 100)")
    p.add_argument("--growth-rate", type=float, default=1e-5, help="dD/dt of the B disks (default 1e-5)")
    p.add_argument("--compress-rate", type=float, default=1e-5, help="LS growth rate to jamming (default 1e-5)")
    p.add_argument("--max-pressure", type=float, default=1e12, help="reduced pressure of jamming (default 1e12)")
    p.add_argument("--cell-step", type=float, default=0.1, help="alpha of the deforming cell (default 0.1)")
    p.add_argument("--seed", type=int, required=True, help="seed of the start velocities")
    p.add_argument("--out", required=True, help="jammed packing netCDF (phi_J, s_c in its attributes)")
    p.add_argument("--timeseries", help="time series of the compression to jamming")
    p.add_argument("--growth-timeseries", help="time series of the growth (Fig. 13.14)")
    p.set_defaults(func=cmd_glass_microsegregated)

    p = subparsers.add_parser("glass-soc", help=cmd_glass_soc.__doc__.split("\n\n")[0])
    p.add_argument("packing", help="start packing netCDF (a snapshot; its positions are the cell centres)")
    p.add_argument("--dmu", type=float, default=1.0, help="cell size Delta mu in radii (default 1: twice the disk)")
    p.add_argument("--growth-rate", type=float, default=1e-6, help="d<D>/dt of the disks (default 1e-6)")
    p.add_argument("--max-pressure", type=float, default=1e3,
                   help="stop at this reduced pair-collision pressure (default 1e3)")
    p.add_argument("--window", type=float, default=100.0, help="collisions per disk per record (default 100)")
    p.add_argument("--seed", type=int, required=True, help="seed of the start velocities")
    p.add_argument("--out", required=True, help="final packing netCDF")
    p.add_argument("--timeseries", required=True, help="per-segment time series netCDF")
    p.add_argument("--checkpoint", help="checkpoint file (resumes a stopped run)")
    p.set_defaults(func=cmd_glass_soc)

    p = subparsers.add_parser("glass-soc-summary", help=cmd_glass_soc_summary.__doc__.split("\n\n")[0])
    p.add_argument("--soc", nargs="+", required=True, help="glass-soc time series")
    p.add_argument("--relaxed", nargs="+", required=True,
                   help="hardpack eos runs of their final packings, in the same order")
    p.add_argument("--out", required=True, help="summary netCDF")
    p.set_defaults(func=cmd_glass_soc_summary)

    p = subparsers.add_parser("glass-microsegregated-summary",
                              help=cmd_glass_microsegregated_summary.__doc__.split("\n\n")[0])
    p.add_argument("files", nargs="+", help="jammed packings of glass-microsegregated")
    p.add_argument("--out", required=True, help="summary netCDF")
    p.set_defaults(func=cmd_glass_microsegregated_summary)
