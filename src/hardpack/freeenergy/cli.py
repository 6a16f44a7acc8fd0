"""``hardpack bcmd PACKING.nc --out RESULT.nc``: BCMD free energy of a stored packing;
``hardpack bcmd-simplex PACKING.nc --jamming VERDICT.nc --out RESULT.nc``: BCMD of its rattler-free
backbone against the exact jamming simplex (:mod:`hardpack.freeenergy.isostatic`);
``hardpack bcmd-ladder --out CHECKS.nc``: the cheap checks of :mod:`hardpack.freeenergy.ladder`.

The cells are centred on the stored positions. ``--phi`` rescales all radii to that volume
fraction (e.g. a lattice at phi = 0.545); ``--delta`` shrinks them by (1 - delta) (a jammed
packing near its jamming point, Donev Eq. 6.18). Prints Delta f = (d/2) ln(K/K0), f_c, f and the
excess over the ideal gas; writes the per-segment series (hardpack.freeenergy.bcmd.run_bcmd).
"""

from __future__ import annotations

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.bcmd import FROZEN_MODES, run_bcmd


def register(subparsers) -> None:
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
    p.add_argument(
        "--gamma0",
        type=float,
        default=1e-3,
        help="shrink rate at dmu_max (default 1e-3)",
    )
    p.add_argument(
        "--theta",
        type=float,
        default=1.0,
        help="schedule exponent: gamma = gamma0 (dmu/dmu_max)^theta (default 1)",
    )
    p.add_argument(
        "--frozen",
        choices=FROZEN_MODES,
        default="particle",
        help="freeze particle 0 (default) or measure K in the CM frame",
    )
    p.add_argument("--seed", type=int, default=0, help="velocity seed (default 0)")
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
    p.add_argument("--gamma0", type=float, default=0.01, help="shrink rate at dmu_max")
    p.add_argument("--theta", type=float, default=1.0, help="schedule exponent")
    p.add_argument("--frozen", choices=FROZEN_MODES, default="particle",
                   help="freeze particle 0 (default) or measure K in the CM frame")
    p.add_argument("--seed", type=int, default=0, help="velocity seed (default 0)")
    p.set_defaults(func=cmd_bcmd_simplex)

    p = subparsers.add_parser(
        "bcmd-ladder",
        help="The cheap BCMD checks against exact values (disjoint cells, billiard, simplex).",
    )
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_bcmd_ladder)


def cmd_bcmd_ladder(args) -> int:
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
