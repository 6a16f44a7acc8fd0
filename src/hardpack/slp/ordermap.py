"""The phi-T order map of SLP packings (Torquato & Jiao 2010, Fig. 6 and Sec. VI).

One row per packing: density phi (rattlers included, as in Fig. 6 and Sec. VI), its number of
spheres N (settings may use different cell sizes: small cells crystallise partly), translational
order metric T (:func:`hardpack.structure.order.translational_order`, FCC reference at the same
density, our shell convention: T = 1 for FCC, ~0 for an ideal gas), the SLP settings that made
it (influence radius alpha = gamma / D, bound widths, LP solver) and its jamming verdict
(:func:`hardpack.jamming.verify` output written by ``hardpack verify``).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.io import load_judged_packings
from hardpack.structure.order import translational_order

SETTINGS = ("alpha", "strain_bound", "shear_bound", "displacement_bound", "lp_method", "seed")
VERDICT = ("strict", "collective", "z_mean", "rattler_fraction")


def order_map_summary(packing_paths, verdict_paths) -> xr.Dataset:
    """phi, T, settings and verdict of each packing; ``verdict_paths[k]`` judges ``packing_paths[k]``.

    Torquato & Jiao 2010, Fig. 6; columns described in the module docstring.

    Parameters
    ----------
    packing_paths : sequence of str or os.PathLike
        3D SLP packing files; each must carry the attributes ``alpha``, ``strain_bound``,
        ``shear_bound``, ``displacement_bound``, ``lp_method`` and ``seed``.
    verdict_paths : sequence of str or os.PathLike
        Their jamming verdicts (``hardpack verify`` output), in the same order.

    Returns
    -------
    xarray.Dataset
        One row per packing along ``packing``: ``phi``, ``N``, ``T``, the settings above and
        the verdict ``strict``, ``collective``, ``z_mean``, ``rattler_fraction``; attributes
        ``hardpack_kind`` = "slp_order_map" and ``T_convention``.

    Raises
    ------
    InvalidInputError
        If there are no packings or not one verdict per packing, a verdict judges another
        packing, or a packing is not 3D.
    StoreError
        If a file is missing, unreadable or of the wrong kind.
    """
    packing_paths, verdict_paths = list(packing_paths), list(verdict_paths)
    judged = load_judged_packings(packing_paths, verdict_paths, "order map")
    rows = {name: [] for name in ("phi", "N", "T", *SETTINGS, *VERDICT)}
    for path, verdict_path, (ds, packing, verdict) in zip(packing_paths, verdict_paths, judged):
        if packing.dim != 3:
            raise InvalidInputError(f"{path}: the order map is 3D (FCC reference), got d = {packing.dim}")
        rows["phi"].append(packing.phi)
        rows["N"].append(packing.n_particles)
        rows["T"].append(translational_order(packing))
        for name in SETTINGS:
            rows[name].append(ds.attrs[name])
        for name in VERDICT:
            rows[name].append(verdict.attrs[name])
    data = {name: ("packing", np.asarray(values)) for name, values in rows.items()}
    attrs = {"hardpack_kind": "slp_order_map",
             "T_convention": "hardpack.structure.order.translational_order defaults (7 FCC shells)"}
    return xr.Dataset(data, attrs=attrs)
