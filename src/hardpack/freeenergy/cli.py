"""``hardpack bcmd PACKING.nc --out RESULT.nc``: BCMD free energy of a stored packing;
``hardpack bcmd-simplex PACKING.nc --jamming VERDICT.nc --out RESULT.nc``: BCMD of its rattler-free
backbone against the exact jamming simplex (:mod:`hardpack.freeenergy.isostatic`);
``hardpack bcmd-ladder --out CHECKS.nc``: the cheap checks of :mod:`hardpack.freeenergy.ladder`;
``hardpack bcmd-ellipse PACKING.nc --out RESULT.nc``: a jammed ellipse packing made isostatic by
frozen centroids, its exact simplex and linearised BCMD (:mod:`hardpack.freeenergy.ellipse_bcmd`).

The cells are centred on the stored positions. ``--phi`` rescales all radii to that volume
fraction (e.g. a lattice at phi = 0.545); ``--delta`` shrinks them by (1 - delta) (a jammed
packing near its jamming point, Donev Eq. 6.18). Prints Delta f = (d/2) ln(K/K0), f_c, f and the
excess over the ideal gas; writes the per-segment series (hardpack.freeenergy.bcmd.run_bcmd).
"""

from __future__ import annotations

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.bcmd import FROZEN_MODES, run_bcmd


def register(subparsers) -> None:
    """Add the subcommands ``bcmd``, ``bcmd-simplex``, ``bcmd-ladder``, ``bcmd-ellipse``,
    ``ellipse-lattice``, ``bcmd-ellipse-ladder`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    p = subparsers.add_parser(
        "bcmd",
        help="Bounding-cell MD free energy of a packing (Donev ch. 6).",
        description=__doc__.splitlines()[0],
    )
    p.add_argument("packing", help="packing netCDF file (hardpack.io.save_packing)")
    p.add_argument("--out", required=True, help="output netCDF file")
    size = p.add_mutually_exclusive_group()
    size.add_argument(
        "--phi", type=float, help="rescale the radii to this volume fraction"
    )
    size.add_argument(
        "--delta", type=float, help="shrink the radii by the factor (1 - delta)"
    )
    p.add_argument(
        "--dmu-max",
        type=float,
        required=True,
        help="initial cell size Delta mu_max, in units of the particle radius",
    )
    p.add_argument(
        "--dmu-min",
        type=float,
        default=None,
        help="final cell size (default: the disjoint-cell point)",
    )
    _add_schedule_and_seed(p, gamma0=1e-3, theta=1.0)
    p.add_argument(
        "--frozen",
        choices=FROZEN_MODES,
        default="particle",
        help="freeze particle 0 (default) or measure K in the CM frame",
    )
    p.add_argument(
        "--reset-ratio",
        type=float,
        default=None,
        help="re-draw velocities when K grew by this factor (rattlers; default off)",
    )
    p.set_defaults(func=cmd_bcmd)

    p = subparsers.add_parser(
        "bcmd-simplex",
        help="BCMD of a jammed packing's rattler-free backbone vs its exact simplex (Donev ch. 6, Table 6.1).",
        description=__doc__.splitlines()[2],
    )
    p.add_argument("packing", help="jammed packing netCDF file")
    p.add_argument("--jamming", required=True,
                   help="its jamming verdict (hardpack verify output with the 'rattler' mask)")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--delta", type=float, default=1e-8,
                   help="shrink factor 1 - delta of the radii (default 1e-8)")
    p.add_argument("--contact-tol", type=float, default=None,
                   help="relative contact gap (default: the verdict's delta, capped at delta/10)")
    p.add_argument("--dmu-max-ratio", type=float, default=100.0,
                   help="initial cell size in units of the disjoint-cell point (default 100)")
    _add_schedule_and_seed(p, gamma0=0.01, theta=1.0)
    p.add_argument("--frozen", choices=FROZEN_MODES, default="particle",
                   help="freeze particle 0 (default) or measure K in the CM frame")
    p.set_defaults(func=cmd_bcmd_simplex)

    p = subparsers.add_parser(
        "bcmd-ladder",
        help="The cheap BCMD checks against exact values (disjoint cells, billiard, simplex).",
    )
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_bcmd_ladder)

    p = subparsers.add_parser(
        "bcmd-ellipse",
        help="Exact simplex and BCMD free energy of a jammed ellipse packing (Donev ch. 6, sec. 6.4.3).",
    )
    p.add_argument("packing", help="jammed 2D ellipse packing netCDF file")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.add_argument("--delta", type=float, default=1e-4, help="shrink factor 1 - delta (default 1e-4)")
    p.add_argument("--contact-tol", type=float, default=1e-6,
                   help="contacts: Perram-Wertheim mu - 1 <= this (default 1e-6)")
    p.add_argument("--dmu-max", type=float, default=1.5e-2, help="initial cell size (default 1.5e-2)")
    _add_schedule_and_seed(p, gamma0=1e-3, theta=0.5)
    p.add_argument("--freeze", choices=("full", "centroid"), default="full",
                   help="the fewest particles frozen entirely (default; Donev 2006 Fig. 6.5: 96 free "
                        "and four frozen) or just enough centroids, orientations free")
    p.add_argument("--freeze-seed", type=int, default=0,
                   help="seed of the order in which frozen sets are tried (default 0)")
    p.add_argument("--exact-only", action="store_true", help="the exact simplex only, no BCMD")
    p.set_defaults(func=cmd_bcmd_ellipse)

    p = subparsers.add_parser(
        "ellipse-lattice",
        help="Start of the isostatic ellipse packing: lattice disks turned into ellipses (Donev 2006, sec. 6.4.3).",
    )
    p.add_argument("--out", required=True, help="output packing netCDF file")
    p.add_argument("--alpha", type=float, default=2.0, help="aspect ratio (default 2)")
    p.add_argument("--spread", type=float, default=0.6,
                   help="width of the uniform orientation distribution, radians (default 0.6)")
    p.add_argument("--seed", type=int, default=0, help="orientation seed (default 0)")
    p.set_defaults(func=cmd_ellipse_lattice)

    p = subparsers.add_parser(
        "bcmd-ellipse-ladder",
        help="Independent ellipses in shrinking cells of their own shape: BCMD against 3 ln(dmu0/dmu1).",
    )
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_bcmd_ellipse_ladder)


def _add_schedule_and_seed(p, *, gamma0: float, theta: float) -> None:
    """The options of a BCMD run's shrink schedule (:func:`hardpack.freeenergy.bcmd.shrink_schedule`)
    and its velocity seed, with the command's defaults."""
    p.add_argument("--gamma0", type=float, default=gamma0, help=f"shrink rate at dmu_max (default {gamma0:g})")
    p.add_argument("--theta", type=float, default=theta,
                   help=f"schedule exponent: gamma = gamma0 (dmu/dmu_max)^theta (default {theta:g})")
    p.add_argument("--seed", type=int, default=0, help="velocity seed (default 0)")


def cmd_ellipse_lattice(args) -> int:
    """Start of the isostatic ellipse packing: lattice disks turned into ellipses (Donev 2006,
    sec. 6.4.3), written to ``args.out``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack ellipse-lattice``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.freeenergy.ellipses import lattice_ellipses
    from hardpack.io import save_packing

    packing = lattice_ellipses(alpha=args.alpha, spread=args.spread, seed=args.seed)
    save_packing(packing, args.out, seed=args.seed)
    print(f"{packing.n_particles} ellipses, alpha = {args.alpha}, phi = {packing.phi:.4f}; written {args.out}")
    return 0


def cmd_bcmd_ellipse_ladder(args) -> int:
    """Independent ellipses in shrinking cells of their own shape: BCMD against 3 ln(dmu0/dmu1)
    (:func:`hardpack.freeenergy.ellipse_bcmd.disjoint_cells_check`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack bcmd-ellipse-ladder``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.freeenergy.ellipse_bcmd import disjoint_cells_check
    from hardpack.io import write_dataset

    ds = disjoint_cells_check()
    write_dataset(ds, args.out)
    print(f"relative deviations {ds['rel_dev'].values.tolist()}, {float(ds['seconds'].sum()):.1f} s")
    return 0


def cmd_bcmd_ellipse(args) -> int:
    """Exact simplex and BCMD free energy of a jammed ellipse packing made isostatic by frozen
    centroids (Donev 2006, sec. 6.4.3).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack bcmd-ellipse``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    import dataclasses

    import numpy as np
    import xarray as xr

    from hardpack.freeenergy.ellipse_bcmd import ellipse_bcmd
    from hardpack.freeenergy.ellipses import cell_log_volume, freeze_to_isostatic
    from hardpack.io import load_packing, write_dataset

    packing = load_packing(args.packing)
    fixed_t, fixed_r, ref = freeze_to_isostatic(packing, args.delta, args.contact_tol,
                                                seed=args.freeze_seed, mode=args.freeze)
    ax = packing.shape.semiaxes
    alphas = np.unique(np.round(ax.max(axis=1) / ax.min(axis=1), 9))
    common = {"source": str(args.packing), "n_fixed_translation": len(fixed_t),
              "n_fixed_rotation": len(fixed_r), "freeze_seed": args.freeze_seed,
              "freeze": args.freeze,
              "f_c_j": cell_log_volume(float(alphas[0])) if alphas.size == 1 and alphas[0] > 1 else np.nan}
    print(f"N = {ref.n_particles}, M = {ref.n_contacts}, N_f = {ref.n_dof}: {len(fixed_t)} frozen "
          f"centroids {fixed_t.tolist()}, {len(fixed_r)} frozen orientations {fixed_r.tolist()}")
    print(f"exact: f_J - f_c^J = {ref.f_j_minus_fcj:.5f} (delta -> 0), Delta f = {ref.delta_f:.5f} at "
          f"delta = {args.delta:g} (dmu_min = {ref.dmu_min:.6g}); smallest force {ref.min_force:.3g}, "
          f"next gap {ref.next_gap:.3g}")
    if args.exact_only:
        attrs = {k: v for k, v in dataclasses.asdict(ref).items()}
        attrs.update(common, hardpack_kind="bcmd_ellipse", exact=ref.delta_f, delta=args.delta,
                     contact_tol=args.contact_tol, fixed_translation=fixed_t, fixed_rotation=fixed_r)
        write_dataset(xr.Dataset(attrs=attrs), args.out, seed=args.seed)
        return 0
    ds = ellipse_bcmd(packing, delta=args.delta, contact_tol=args.contact_tol,
                      fixed_translation=fixed_t, fixed_rotation=fixed_r, dmu_max=args.dmu_max,
                      gamma0=args.gamma0, theta=args.theta, seed=args.seed)
    ds.attrs.update(common)
    write_dataset(ds, args.out, seed=args.seed)
    a = ds.attrs
    print(f"BCMD {a['bcmd']:.5f} against exact {a['exact']:.5f} (difference {a['diff']:+.5f}); "
          f"{a['n_events']} events, {a['seconds']:.1f} s; {a['vertices_outside']} of "
          f"{a['n_vertices']} simplex vertices outside the cells at dmu_max")
    return 0


def cmd_bcmd_ladder(args) -> int:
    """The cheap BCMD checks against exact values
    (:func:`hardpack.freeenergy.ladder.ladder_dataset`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack bcmd-ladder``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.freeenergy.ladder import ladder_dataset
    from hardpack.io import write_dataset

    ds = ladder_dataset()
    write_dataset(ds, args.out)
    for check in ds.check.values:
        row = ds.sel(check=check)
        print(f"{check}: deviation from exact {float(row.value):.3g} +- {float(row.error):.2g} "
              f"({int(row.n_samples)} samples, {float(row.seconds):.1f} s)")
    return 0


def cmd_bcmd_simplex(args) -> int:
    """BCMD of a jammed packing's rattler-free backbone against its exact simplex (Donev 2006,
    Table 6.1; :func:`hardpack.freeenergy.isostatic.simplex_test`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack bcmd-simplex``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.freeenergy.isostatic import simplex_test
    from hardpack.io import load_dataset, load_packing, write_dataset

    packing = load_packing(args.packing)
    verdict = load_dataset(args.jamming, kind="jamming")
    tol = args.contact_tol
    if tol is None:
        tol = min(float(verdict.attrs["delta"]), args.delta / 10)
    ds = simplex_test(
        packing, verdict["rattler"].values.astype(bool), delta=args.delta, contact_tol=tol,
        dmu_max_ratio=args.dmu_max_ratio, gamma0=args.gamma0, theta=args.theta,
        frozen=args.frozen, seed=args.seed,
    )
    ds.attrs.update(source=str(args.packing), verdict=str(args.jamming), seed=args.seed)
    write_dataset(ds, args.out, seed=args.seed)
    a = ds.attrs
    print(
        f"backbone N = {a['n_backbone']}, M = {a['n_contacts']}, isostaticity gap "
        f"{a['isostaticity_gap']}; exact {a['exact']:.5f}, BCMD {a['bcmd']:.5f} "
        f"(relative difference {a['rel_diff']:+.2e}), {a['n_events']} events, "
        f"{a['seconds_bcmd']:.1f} s"
    )
    return 0


def _sized(packing, phi, delta):
    if phi is not None:
        if not 0 < phi < 1:
            raise InvalidInputError(f"--phi must be in (0, 1), got {phi}")
        return packing.replace(
            radii=packing.radii * (phi / packing.phi) ** (1.0 / packing.dim)
        )
    if delta is not None:
        if not 0 < delta < 1:
            raise InvalidInputError(f"--delta must be in (0, 1), got {delta}")
        return packing.replace(radii=packing.radii * (1.0 - delta))
    return packing


def cmd_bcmd(args) -> int:
    """Bounding-cell MD free energy of a stored packing (module docstring; Donev 2006, ch. 6).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack bcmd``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import load_packing, write_dataset

    packing = _sized(load_packing(args.packing), args.phi, args.delta)
    res = run_bcmd(
        packing,
        dmu_max=args.dmu_max,
        dmu_min=args.dmu_min,
        gamma0=args.gamma0,
        theta=args.theta,
        frozen=args.frozen,
        seed=args.seed,
        reset_ratio=args.reset_ratio,
    )
    ds = res.to_dataset()
    ds.attrs["source"] = str(args.packing)
    if args.delta is not None:
        ds.attrs["delta"] = args.delta
    write_dataset(ds, args.out, seed=args.seed)
    a = ds.attrs
    print(
        f"N = {a['n_particles']}, d = {a['dim']}, phi = {a['phi']:.6g}, frozen = {a['frozen']}, "
        f"dmu {a['dmu_max']:.4g} -> {a['dmu_min']:.6g}, {a['n_events']} events"
    )
    print(
        f"Delta f = (d/2) ln(K/K0) = {res.delta_f:.5f}  (= f_J - f_c^J when dmu_min = delta)"
    )
    print(
        f"f_c(dmu_min) = {res.f_c:.5f}, f = {res.f:.5f}, excess over ideal gas = {res.excess:.5f}"
    )
    print(f"written {args.out}")
    return 0
