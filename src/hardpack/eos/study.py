"""Polydisperse systems and their moment-matched equivalents: jamming and fluid-EOS runs (Ogarko ch. 3).

A *system* is a size distribution (spec as in :func:`hardpack.distributions.from_spec`) in one of
three forms (:data:`SYSTEMS`):

- ``poly``: the distribution itself (systematic sampling, Ogarko 2014, sec. 3.1.3);
- ``bi``: its equivalent bidisperse mixture, same <a^0>..<a^3> (Eqs. 3.20-3.21, Table 3.1);
- ``tri``: its maximally equivalent tridisperse mixture, same <a^0>..<a^5> (ch. 3.2, Tables 3.3-3.4).

:func:`jam` grows a random start to jamming with the LS engine (two stages, see :class:`JamProtocol`)
and :func:`fluid_pressure` measures the equilibrium reduced pressure Z at fixed phi and compares it with
BMCSL (Eq. 3.9) for the realised radii. Both run in 3D in a periodic cube with masses 1, kT = 1.
:func:`equivalents_dataset` tabulates the moments and both equivalents over a family's width.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np
import xarray as xr

from hardpack.distributions import Distribution, from_spec
from hardpack.eos import moments as mo
from hardpack.eos.theory import bmcsl
from hardpack.errors import InvalidInputError

SYSTEMS = ("poly", "bi", "tri")
#: the width parameter of each family of the study (omega = a_max/a_min, sigma of ln a)
WIDTH = {"uniform_size": "omega", "uniform_volume": "omega", "power_law": "omega", "lognormal": "sigma"}


def width_of(spec: dict) -> tuple[str, float]:
    """(family, width) of a distribution spec, e.g. ("uniform_volume", 10.0).

    Parameters
    ----------
    spec : dict
        Distribution spec (:func:`hardpack.distributions.from_spec`).

    Returns
    -------
    family : str
        The distribution kind.
    width : float
        Its width parameter.
    """
    if not isinstance(spec, dict) or spec.get("kind") not in WIDTH:
        raise InvalidInputError(f"the study needs a distribution of kind {sorted(WIDTH)}, got {spec!r}")
    return spec["kind"], float(spec[WIDTH[spec["kind"]]])


def system_distribution(spec: dict, system: str) -> Distribution:
    """The distribution ``spec`` as the ``system`` (poly, bi or tri), all with the same <a>.

    Parameters
    ----------
    spec : dict
        Distribution spec.
    system : str
        "poly", "bi" or "tri".

    Returns
    -------
    Distribution
        The distribution itself, or its bi- or tridisperse equivalent mixture (Ogarko 2014, ch. 3).
    """
    if system not in SYSTEMS:
        raise InvalidInputError(f"system must be one of {SYSTEMS}, got {system!r}")
    dist = from_spec(spec)
    if system == "bi":
        return mo.equivalent_bidisperse(dist).mixture
    if system == "tri":
        return mo.equivalent_tridisperse(dist).mixture
    return dist


@dataclass(frozen=True)
class JamProtocol:
    """LS compression from an RSA start at ``init_phi``: growth rate ``growth_rate`` until the window
    pressure reaches ``switch_pressure``, then ``final_growth_rate`` until ``max_pressure``
    (hardpack.md.compress's two-stage protocol; Gamma as defined there).

    Ogarko grows at one constant rate (Ogarko 2014, sec. 3.1.3); the jamming density depends on the rate (it rises
    by <= 1 % as Gamma decreases, inset of Fig. 3.7(a)), so poly and equivalent systems are compared at the
    same protocol and N only.

    Attributes
    ----------
    n : int
        Number of particles, >= 2.
    init_phi : float
        Volume fraction of the RSA start.
    growth_rate : float
        Gamma of the first stage.
    switch_pressure : float
        Reduced pressure ending the first stage.
    final_growth_rate : float
        Gamma of the second stage.
    max_pressure : float
        Reduced pressure ending the compression.
    """

    n: int = 1000
    init_phi: float = 0.2
    growth_rate: float = 0.02
    switch_pressure: float = 1e3
    final_growth_rate: float = 0.002
    max_pressure: float = 1e12

    def __post_init__(self):
        if int(self.n) != self.n or self.n < 2:
            raise InvalidInputError(f"n must be an integer >= 2, got {self.n!r}")
        for name in ("growth_rate", "final_growth_rate"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) > 0):
                raise InvalidInputError(f"{name} must be a positive number, got {getattr(self, name)!r}")
        if not 1 < self.switch_pressure < self.max_pressure:
            raise InvalidInputError(
                f"need 1 < switch_pressure < max_pressure, got {self.switch_pressure} and {self.max_pressure}"
            )


def large_species_crystallinity(packing, solid: np.ndarray) -> float:
    """Fraction of solid-like particles among those larger than the mean radius (the large species of
    a bidisperse mixture; crystallisation of that species breaks the bidisperse equivalence, sec. 3.1.3).

    Parameters
    ----------
    packing : Packing
        The packing.
    solid : numpy.ndarray of bool, shape (N,)
        Solid-like particles (:func:`hardpack.structure.order.crystallinity`).

    Returns
    -------
    float
        The fraction (NaN without particles above the mean radius).
    """
    large = packing.radii > packing.radii.mean()
    return float(solid[large].mean()) if large.any() else math.nan


def jam(spec: dict, system: str, seed: int, protocol: JamProtocol = JamProtocol(), checkpoint=None,
        keep_checkpoint: bool = False):
    """Jam one system: RSA start (seed), then the two-stage LS compression (velocities from seed).

    ``checkpoint``: path of the compression's checkpoint (:func:`hardpack.md.compress`): a killed run
    started again resumes there (the RSA start is the same for the same seed) and ends identical;
    removed at the end unless ``keep_checkpoint`` (the caller removes it once the result is written).
    Returns the :class:`hardpack.md.CompressResult` with ``stats`` extended by the study's attributes
    (family, width, system, O1, O2, cpu_time, crystallinity and that of the large particles;
    cpu_time counts this process only, ``wall_time`` the whole run, resumed parts included).

    Parameters
    ----------
    spec : dict
        Distribution spec.
    system : str
        "poly", "bi" or "tri".
    seed : int
        Seed of the start and the velocities.
    protocol : JamProtocol, optional
        The compression.
    checkpoint : str or os.PathLike, optional
        Checkpoint file.
    keep_checkpoint : bool, optional
        Keep the checkpoint at the end.

    Returns
    -------
    hardpack.md.CompressResult
        As above.
    """
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, compress
    from hardpack.structure.order import crystallinity

    family, width = width_of(spec)
    dist = system_distribution(spec, system)
    start = time.process_time()
    packing = random_packing(protocol.n, 3, dist, protocol.init_phi, seed)
    result = compress(packing, protocol.growth_rate, seed, stop=StopCriteria(max_pressure=protocol.max_pressure),
                      final_growth_rate=protocol.final_growth_rate, switch_pressure=protocol.switch_pressure,
                      checkpoint=checkpoint, keep_checkpoint=keep_checkpoint)
    cpu = time.process_time() - start
    solid = crystallinity(result.packing)["solid"].values
    o1, o2 = mo.dimensionless_moments(result.packing.radii)
    result.stats.update(
        family=family, width=width, system=system, O1=o1, O2=o2, cpu_time=cpu, init_phi=protocol.init_phi,
        crystallinity=float(solid.mean()), crystallinity_large=large_species_crystallinity(result.packing, solid),
        study_protocol=str(asdict(protocol)),
    )
    return result


def fluid_pressure(spec: dict, system: str, phi: float, seed: int, n: int = 500, collisions: int = 400_000,
                   prep_rate: float = 0.1) -> dict:
    """Equilibrium Z at volume fraction ``phi`` (NVE event-driven MD, block error bar) and BMCSL.

    RSA start at min(phi, 0.2), LS growth at ``prep_rate`` exactly to phi, then
    :func:`hardpack.md.equilibrate` over ``collisions`` collisions (a quarter more are discarded first).
    BMCSL (Eq. 3.9) uses O1, O2 of the realised radii, so the comparison is free of sampling error;
    Ogarko finds Z within 1 % of BMCSL for phi < 0.54 (Ogarko 2014, sec. 3.1.3 and Fig. 3.1; sec. 3.2).

    Parameters
    ----------
    spec : dict
        Distribution spec.
    system : str
        "poly", "bi" or "tri".
    phi : float
        Volume fraction, in (0, 0.6).
    seed : int
        Random seed.
    n : int, optional
        Number of particles.
    collisions : int, optional
        Collisions of the measurement.
    prep_rate : float, optional
        Gamma of the preparation.

    Returns
    -------
    dict
        family, width, system, phi, Z, Z_err, Z_bmcsl, rel_dev, O1, O2, N, seed, collisions, cpu_time.

    Raises
    ------
    InvalidInputError
        For phi outside (0, 0.6).
    """
    from hardpack.initial import random_packing
    from hardpack.md import StopCriteria, compress, equilibrate

    if not 0 < phi < 0.6:
        raise InvalidInputError(f"fluid phi must lie in (0, 0.6), got {phi}")
    family, width = width_of(spec)
    dist = system_distribution(spec, system)
    start = time.process_time()
    packing = random_packing(n, 3, dist, min(phi, 0.2), seed)
    if phi > packing.phi * (1 + 1e-9):  # (a target within round-off of the start overshoots in compress)
        packing = compress(packing, prep_rate, seed, stop=StopCriteria(max_pressure=None, target_phi=phi)).packing
    if abs(packing.phi - phi) > 1e-9 * phi:
        raise RuntimeError(f"preparation reached phi = {packing.phi}, not the requested {phi}")
    res = equilibrate(packing, seed, collisions)
    o1, o2 = mo.dimensionless_moments(packing.radii)
    z_theory = float(bmcsl(res.phi, o1, o2))
    return dict(family=family, width=width, system=system, phi=res.phi, Z=res.Z, Z_err=res.Z_err,
                Z_bmcsl=z_theory, rel_dev=res.Z / z_theory - 1, O1=o1, O2=o2, N=n, seed=seed,
                collisions=res.collisions, cpu_time=time.process_time() - start)


# --- summaries -------------------------------------------------------------------------------------

JAM_VARIABLES = ("phi", "Z", "collisions", "cpu_time", "crystallinity", "crystallinity_large", "O1", "O2")


JAM_STUDIES = ("jam", "crystallisation")


def jam_summary(packings, study: str = "jam") -> xr.Dataset:
    """Jammed packings of one family (Datasets written by ``hardpack poly-jam``) as one Dataset over
    (width, system, seed): phi_J (the final phi; phi_J - phi ~ 3 phi / Z <= 1e-11 at Z = 1e12) and
    the run statistics. Missing combinations are NaN. ``study`` (attribute) tells the validation
    what the runs test: "jam", the equivalence of the mixtures at one protocol, or
    "crystallisation", the slow runs for the large-species crystallisation of Ogarko 2014, sec. 3.1.3.

    Parameters
    ----------
    packings : iterable of xarray.Dataset
        Jammed packings of one family.
    study : str, optional
        "jam" or "crystallisation".

    Returns
    -------
    xarray.Dataset
        Over (width, system, seed).

    Raises
    ------
    InvalidInputError
        For an unknown study, no packings or several families.
    """
    if study not in JAM_STUDIES:
        raise InvalidInputError(f"study must be one of {JAM_STUDIES}, got {study!r}")
    packings = list(packings)
    if not packings:
        raise InvalidInputError("jam_summary needs at least one packing")
    families = {ds.attrs.get("family") for ds in packings}
    if len(families) != 1 or None in families:
        raise InvalidInputError(f"jam_summary combines the packings of one family, got families {families}")
    widths = sorted({float(ds.attrs["width"]) for ds in packings})
    seeds = sorted({int(ds.attrs["seed"]) for ds in packings})
    systems = [s for s in SYSTEMS if any(ds.attrs["system"] == s for ds in packings)]
    shape = (len(widths), len(systems), len(seeds))
    data = {name: np.full(shape, np.nan) for name in JAM_VARIABLES}
    for ds in packings:
        at = (widths.index(float(ds.attrs["width"])), systems.index(ds.attrs["system"]),
              seeds.index(int(ds.attrs["seed"])))
        for name in JAM_VARIABLES:
            data[name][at] = float(ds.attrs[name])
    dims = ("width", "system", "seed")
    out = xr.Dataset({("phi_J" if k == "phi" else k): (dims, v) for k, v in data.items()},
                     coords={"width": widths, "system": systems, "seed": seeds})
    first = packings[0].attrs
    out.attrs.update(hardpack_kind="eos_jam_summary", family=families.pop(), width_name=WIDTH[first["family"]],
                     N=int(packings[0].sizes["particle"]), study_protocol=first["study_protocol"], study=study)
    return out


def fluid_dataset(rows: list[dict]) -> xr.Dataset:
    """Fluid runs of one distribution (dicts from :func:`fluid_pressure`) over (system, phi).

    Parameters
    ----------
    rows : list of dict
        Results of :func:`fluid_pressure`.

    Returns
    -------
    xarray.Dataset
        Z, Z_err, Z_bmcsl, O1, O2, cpu_time and rel_dev over (system, phi).

    Raises
    ------
    InvalidInputError
        Without runs.
    """
    if not rows:
        raise InvalidInputError("no fluid runs given")
    systems = [s for s in SYSTEMS if any(r["system"] == s for r in rows)]
    phis = sorted({round(r["phi"], 12) for r in rows})
    names = ("Z", "Z_err", "Z_bmcsl", "O1", "O2", "cpu_time")
    data = {k: np.full((len(systems), len(phis)), np.nan) for k in names}
    for r in rows:
        at = (systems.index(r["system"]), phis.index(round(r["phi"], 12)))
        for k in names:
            data[k][at] = r[k]
    ds = xr.Dataset({k: (("system", "phi"), v) for k, v in data.items()}, coords={"system": systems, "phi": phis})
    ds["rel_dev"] = ds["Z"] / ds["Z_bmcsl"] - 1
    ds.attrs.update(hardpack_kind="eos_fluid", family=rows[0]["family"], width=rows[0]["width"], N=rows[0]["N"],
                    seed=rows[0]["seed"], collisions=rows[0]["collisions"])
    return ds


def fluid_summary(datasets) -> xr.Dataset:
    """Fluid datasets of several distributions as one Dataset over (case, system, phi); case labels
    are "family:width".

    Parameters
    ----------
    datasets : iterable of xarray.Dataset
        Fluid datasets (:func:`fluid_dataset`), one per distribution.

    Returns
    -------
    xarray.Dataset
        Over (case, system, phi).

    Raises
    ------
    InvalidInputError
        Without datasets or with duplicate cases.
    """
    datasets = list(datasets)
    if not datasets:
        raise InvalidInputError("fluid_summary needs at least one fluid dataset")
    labels = [f"{ds.attrs['family']}:{float(ds.attrs['width']):g}" for ds in datasets]
    if len(set(labels)) != len(labels):
        raise InvalidInputError(f"duplicate fluid cases {labels}")
    bare = [ds.copy() for ds in datasets]
    for ds in bare:
        ds.attrs = {}
    out = xr.concat(bare, dim="case", join="outer")
    out = out.assign_coords(case=labels, family=("case", [ds.attrs["family"] for ds in datasets]),
                            width=("case", [float(ds.attrs["width"]) for ds in datasets]),
                            N=("case", [int(ds.attrs["N"]) for ds in datasets]))
    out.attrs = {"hardpack_kind": "eos_fluid_summary"}
    return out


def seed_statistics(summary: xr.Dataset) -> xr.Dataset:
    """Mean and standard error over seeds of phi_J per (width, system), and the relative deviation of
    each system from the polydisperse one, dev = phi_J(system)/phi_J(poly) - 1 (ratio of seed means;
    errors added in quadrature). Seeds of different systems are independent runs (different radii).

    Parameters
    ----------
    summary : xarray.Dataset
        A jam summary (:func:`jam_summary`).

    Returns
    -------
    xarray.Dataset
        phi_J_mean, phi_J_sem, n_seeds, dev, dev_sem, crystallinity_large over (width, system); the
        summary's attributes.
    """
    phi = summary["phi_J"]
    count = phi.count("seed")
    mean = phi.mean("seed")
    sem = phi.std("seed", ddof=1) / np.sqrt(count)
    sem = sem.where(count > 1)
    poly_mean, poly_sem = mean.sel(system="poly"), sem.sel(system="poly")
    dev = mean / poly_mean - 1
    dev_sem = (mean / poly_mean) * np.sqrt((sem / mean) ** 2 + (poly_sem / poly_mean) ** 2)
    out = xr.Dataset({"phi_J_mean": mean, "phi_J_sem": sem, "n_seeds": count, "dev": dev, "dev_sem": dev_sem,
                      "crystallinity_large": summary["crystallinity_large"].mean("seed")})
    out.attrs = dict(summary.attrs)
    return out


def equivalents_dataset(kind: str, values, alpha: float | None = None) -> xr.Dataset:
    """Moments and bi-/tridisperse equivalents of a distribution family at each parameter value
    (Ogarko 2014, Tables 3.1, 3.3 and 3.4).

    Parameters
    ----------
    kind : str
        A family of :data:`WIDTH` (uniform_size, uniform_volume, power_law, lognormal).
    values : sequence of float
        The family's width parameter (omega, or sigma for lognormal) at each row.
    alpha : float, optional
        The exponent of a power_law family (required for it, refused for the others).

    Returns
    -------
    xarray.Dataset
        ``hardpack_kind = "eos_equivalents"`` over the width parameter: O1, O2, delta, skewness,
        kurtosis, the bidisperse equivalent (``bi_n1``, ``bi_R``; Table 3.1) and the maximally
        equivalent tridisperse system (``tri_n1``, ``tri_n2``, ``tri_delta1``, ``tri_delta2`` and
        ``tri_radii`` a1 >= a2 >= a3 in units of <a>; Tables 3.3-3.4).

    Raises
    ------
    InvalidInputError
        For an unknown family, or ``alpha`` given without power_law or missing with it.
    """
    if kind not in WIDTH:
        raise InvalidInputError(f"unknown family {kind!r}; choose one of {sorted(WIDTH)}")
    if (kind == "power_law") != (alpha is not None):
        raise InvalidInputError(f"the power_law family needs its exponent alpha (--alpha on the command line) and the "
                                f"others take none; got family {kind!r} with alpha = {alpha!r}")
    param = WIDTH[kind]
    names = (
        "O1",
        "O2",
        "delta",
        "skewness",
        "kurtosis",
        "bi_n1",
        "bi_R",
        "tri_n1",
        "tri_n2",
        "tri_delta1",
        "tri_delta2",
    )
    table = {name: [] for name in names}
    radii = []
    for value in values:
        spec = {"kind": kind, param: float(value)} | ({"alpha": alpha} if alpha is not None else {})
        dist = from_spec(spec)
        bi, tri = mo.equivalent_bidisperse(dist), mo.equivalent_tridisperse(dist)
        row = (
            *mo.dimensionless_moments(dist),
            mo.polydispersity(dist),
            mo.skewness(dist),
            mo.kurtosis(dist),
            bi.n1,
            bi.R,
            tri.n1,
            tri.n2,
            tri.delta1,
            tri.delta2,
        )
        for name, v in zip(names, row):
            table[name].append(v)
        radii.append(tri.radii)
    coords = {param: np.asarray(values, float), "species": [1, 2, 3]}
    data = {name: ((param,), np.array(v)) for name, v in table.items()}
    data["tri_radii"] = ((param, "species"), np.array(radii))
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(hardpack_kind="eos_equivalents", family=kind, source="Ogarko Tables 3.1, 3.3, 3.4")
    if alpha is not None:
        ds.attrs["alpha"] = alpha
    return ds
