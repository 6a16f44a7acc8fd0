"""Packings and results as xarray Datasets in netCDF files.

Packing layout (``hardpack_kind = "packing"``, ``hardpack_format = 2``):

- ``position(particle, dim)``: Cartesian centres
- ``lattice(dim, vector)``: column ``vector = k`` is the k-th lattice vector
- ``species(particle)``: optional integer labels
- the particle shapes, named by the attribute ``shape_kind``
  (:mod:`hardpack.geometry.shapes`):

  - ``"sphere"``: ``radius(particle)``
  - ``"ellipsoid"``: ``semiaxis(particle, axis)`` (body-frame semiaxes) and the orientation,
    ``quaternion(particle, component)`` in 3D (unit quaternions s, p1, p2, p3) or
    ``angle(particle)`` in 2D (radians from the x axis to the first semiaxis)

- the boundary, named by the attribute ``boundary`` (:mod:`hardpack.geometry.boundaries`):

  - ``"periodic"``: nothing more
  - ``"hard_walls"``: ``wall(dim)``, 1 on the axes with hard walls at 0 and L_k, 0 on the periodic ones
  - ``"spherical_container"``: ``container_centre(dim)`` and the scalar ``container_radius``

- attributes: ``N``, ``d``, ``phi``, ``shape_kind``, ``boundary`` and the provenance of
  :func:`hardpack.io.provenance` plus whatever protocol parameters the producer adds
  (``seed``, ``distribution``, ``growth_rate``, ...).

Format 1 (before particle shapes and boundaries) is format 2 without ``shape_kind``, for spheres
in a periodic cell only; such files load as they always did. A file of a newer format than this
code knows is refused with a request to update hardpack. Every number is stored as float64, so a
packing comes back bit for bit.

Every write is atomic: the dataset goes to a temporary file in the destination folder, is
flushed to disk, and replaces the destination with :func:`os.replace`; a crash leaves either the
old file or the new one, never a half-written one.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError, StoreError
from hardpack.geometry.boundaries import HardWalls, SphericalContainer
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids, Spheres
from hardpack.io.atomic import atomic_path
from hardpack.io.provenance import provenance

FORMAT_VERSION = 2
_SHAPE_VARIABLES = ("radius", "semiaxis", "quaternion", "angle")
_BOUNDARY_VARIABLES = ("wall", "container_centre", "container_radius")


def _netcdf_attr(value):
    """Coerce an attribute to a netCDF-storable value (dicts/lists of mixed types become JSON)."""
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (str, int, float, np.integer, np.floating)):
        return value
    if isinstance(value, (list, tuple, np.ndarray)):
        arr = np.asarray(value)
        if arr.ndim == 1 and arr.dtype.kind in "if" and arr.size:
            return arr
    return json.dumps(value, sort_keys=True, default=str)


def _clean_attrs(attrs: dict) -> dict:
    return {str(k): _netcdf_attr(v) for k, v in attrs.items() if v is not None}


def _shape_variables(shape, d: int) -> dict:
    if shape.kind == "sphere":
        return {"radius": (("particle",), np.asarray(shape.radii))}
    if shape.kind == "ellipsoid":
        data = {"semiaxis": (("particle", "axis"), np.asarray(shape.semiaxes))}
        if d == 2:
            data["angle"] = (("particle",), np.asarray(shape.orientations))
        else:
            data["quaternion"] = (("particle", "component"), np.asarray(shape.orientations))
        return data
    raise InvalidInputError(f"cannot store particles of kind {shape.kind!r}")


def _boundary_variables(boundary, d: int) -> dict:
    if boundary.kind == "hard_walls":
        return {"wall": (("dim",), (~boundary.periodic_axes(d)).astype(np.int8))}
    if boundary.kind == "spherical_container":
        return {"container_centre": (("dim",), np.array(boundary.centre)),
                "container_radius": ((), np.float64(boundary.radius))}
    return {}


def packing_to_dataset(packing: Packing, attrs: dict | None = None, extra: dict | None = None) -> xr.Dataset:
    """Dataset of a packing (layout in the module docstring); ``extra`` adds data variables.

    Parameters
    ----------
    packing : Packing
        The packing (spheres or ellipsoids, any boundary).
    attrs : dict, optional
        Extra attributes; ``None`` values are dropped, booleans become ints, and other values
        that netCDF cannot store become JSON strings. They override the standard attributes.
    extra : dict, optional
        Data variables to add, name -> anything ``Dataset.__setitem__`` accepts.

    Returns
    -------
    xarray.Dataset
        ``position(particle, dim)``, ``lattice(dim, vector)``, the shape and boundary variables,
        ``species`` if set, and the attributes ``hardpack_kind`` = "packing",
        ``hardpack_format``, ``N``, ``d``, ``phi``, ``shape_kind``, ``boundary``.

    Raises
    ------
    InvalidInputError
        If the particle shape has no storage layout.
    """
    data = {
        "position": (("particle", "dim"), np.asarray(packing.positions)),
        **_shape_variables(packing.shape, packing.dim),
        "lattice": (("dim", "vector"), np.asarray(packing.lattice)),
        **_boundary_variables(packing.boundary, packing.dim),
    }
    if packing.species is not None:
        data["species"] = (("particle",), np.asarray(packing.species))
    ds = xr.Dataset(data)
    for name, value in (extra or {}).items():
        ds[name] = value
    ds.attrs.update(
        hardpack_kind="packing", hardpack_format=FORMAT_VERSION, N=packing.n_particles,
        d=packing.dim, phi=packing.phi, shape_kind=packing.shape.kind, boundary=packing.boundary.kind,
    )
    ds.attrs.update(_clean_attrs(attrs or {}))
    return ds


def _require(ds: xr.Dataset, source: str, names, what: str) -> None:
    missing = [v for v in names if v not in ds]
    if missing:
        raise StoreError(
            f"{source} is not a hardpack packing: variable(s) {missing} of {what} missing "
            f"(found {sorted(ds.data_vars)})"
        )


def _stray(ds: xr.Dataset, source: str, names, what: str) -> None:
    """Refuse variables of another shape or boundary than the attributes say (a damaged file)."""
    found = [v for v in names if v in ds]
    if found:
        raise StoreError(f"{source} has variable(s) {found}, which do not belong to {what}; the file is "
                         "inconsistent (written by another program or edited?)")


def _shape_from(ds: xr.Dataset, source: str):
    kind = ds.attrs.get("shape_kind", "sphere")
    if kind == "sphere":
        _require(ds, source, ["radius"], "spheres")
        _stray(ds, source, ["semiaxis", "quaternion", "angle"], "spheres")
        return Spheres(ds["radius"].values)
    if kind == "ellipsoid":
        _require(ds, source, ["semiaxis"], "ellipsoids")
        _stray(ds, source, ["radius"], "ellipsoids")
        orient = "angle" if ds.sizes.get("axis") == 2 else "quaternion"
        _require(ds, source, [orient], f"{ds.sizes.get('axis')}-dimensional ellipsoids")
        _stray(ds, source, [{"angle": "quaternion", "quaternion": "angle"}[orient]],
               f"{ds.sizes.get('axis')}-dimensional ellipsoids")
        dims = ("particle", "component") if orient == "quaternion" else ("particle",)
        return Ellipsoids(ds["semiaxis"].transpose("particle", "axis").values,
                          ds[orient].transpose(*dims).values)
    raise StoreError(f"{source} holds particles of shape_kind {kind!r}, which this hardpack does not know "
                     "(known: 'sphere', 'ellipsoid'); update hardpack")


def _boundary_from(ds: xr.Dataset, source: str):
    kind = ds.attrs.get("boundary", "periodic")
    if kind == "periodic":
        _stray(ds, source, _BOUNDARY_VARIABLES, "a periodic cell")
        return "periodic"
    if kind == "hard_walls":
        _require(ds, source, ["wall"], "hard walls")
        _stray(ds, source, ["container_centre", "container_radius"], "hard walls")
        return HardWalls(tuple(np.flatnonzero(ds["wall"].values).tolist()))
    if kind == "spherical_container":
        _require(ds, source, ["container_centre", "container_radius"], "a spherical container")
        _stray(ds, source, ["wall"], "a spherical container")
        return SphericalContainer(ds["container_centre"].values, ds["container_radius"].values)
    raise StoreError(f"{source} has boundary {kind!r}, which this hardpack does not know (known: 'periodic', "
                     "'hard_walls', 'spherical_container'); update hardpack")


def dataset_to_packing(ds: xr.Dataset, source: str = "dataset", **packing_kwargs) -> Packing:
    """Rebuild (and validate) a packing from its Dataset (format 1 or 2); errors name ``source``.

    Parameters
    ----------
    ds : xarray.Dataset
        A packing dataset in the layout of the module docstring.
    source : str, default "dataset"
        Name of the dataset's origin (usually the file path), used in error messages.
    **packing_kwargs
        Passed to :class:`Packing` (e.g. ``allow_overlap``, ``overlap_tol``).

    Returns
    -------
    Packing
        The validated packing, bit for bit as stored.

    Raises
    ------
    StoreError
        If variables of the packing, its shape or its boundary are missing or inconsistent with
        the attributes, the format, shape kind or boundary is unknown (newer than this code), or
        the data do not make a valid packing (e.g. overlaps; the :class:`InvalidInputError`
        message is kept). StoreError is an InvalidInputError.
    """
    _require(ds, source, ["position", "lattice"], "every packing")
    version = ds.attrs.get("hardpack_format", 1)
    if not isinstance(version, (int, np.integer)) or version > FORMAT_VERSION:
        raise StoreError(f"{source} is a packing of format {version!r}; this hardpack reads formats up "
                         f"to {FORMAT_VERSION}: update hardpack")
    try:
        return Packing(
            positions=ds["position"].transpose("particle", "dim").values,
            shape=_shape_from(ds, source),
            lattice=ds["lattice"].transpose("dim", "vector").values,
            species=ds["species"].values if "species" in ds else None,
            boundary=_boundary_from(ds, source),
            **packing_kwargs,
        )
    except StoreError:
        raise
    except InvalidInputError as exc:
        raise StoreError(f"{source} holds an invalid packing: {exc}") from None


def write_dataset(ds: xr.Dataset, path, *, attrs: dict | None = None, config=None, seed=None) -> Path:
    """Atomically write ``ds`` to netCDF at ``path``, adding provenance attributes.

    Existing attributes of ``ds`` win over the provenance defaults except for the version,
    commit and time stamps, which always describe this write.

    Parameters
    ----------
    ds : xarray.Dataset
        The dataset to write; it is not modified (a copy gets the attributes).
    path : str or os.PathLike
        Destination netCDF file; replaced atomically (:func:`hardpack.io.atomic.atomic_path`).
    attrs : dict, optional
        Attributes that override everything else.
    config : object, optional
        Parameters recorded as the JSON attribute ``config`` (:func:`provenance`).
    seed : int, optional
        Seed recorded as the attribute ``seed``.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    path = Path(path)
    out = ds.copy()
    prov = provenance(config=config, seed=seed)
    merged = {k: v for k, v in prov.items() if k in ("config", "seed")}
    merged.update(out.attrs)
    merged.update({k: v for k, v in prov.items() if k not in ("config", "seed")})
    merged.update(attrs or {})
    out.attrs = _clean_attrs(merged)
    with atomic_path(path) as tmp:
        out.to_netcdf(tmp, engine="netcdf4", format="NETCDF4")
    return path


def save_packing(packing: Packing, path, *, attrs: dict | None = None, extra: dict | None = None,
                 config=None, seed=None) -> Path:
    """Atomically write a packing with provenance (see :func:`write_dataset`).

    Parameters
    ----------
    packing : Packing
        The packing to store.
    path : str or os.PathLike
        Destination netCDF file, replaced atomically.
    attrs, extra
        Extra attributes and data variables (:func:`packing_to_dataset`).
    config, seed
        Provenance of the protocol (:func:`write_dataset`).

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    InvalidInputError
        If the particle shape has no storage layout.
    """
    return write_dataset(packing_to_dataset(packing, attrs, extra), path, config=config, seed=seed)


def load_dataset(path, kind: str | None = None) -> xr.Dataset:
    """Load a hardpack netCDF file fully into memory; errors name the file.

    With ``kind`` the file's ``hardpack_kind`` attribute must match.

    Parameters
    ----------
    path : str or os.PathLike
        The netCDF file.
    kind : str, optional
        The expected ``hardpack_kind`` (e.g. "packing", "jamming").

    Returns
    -------
    xarray.Dataset
        The dataset, loaded into memory (the file is closed).

    Raises
    ------
    StoreError
        If the file does not exist, cannot be read as netCDF, or its ``hardpack_kind`` is not
        ``kind``.
    """
    path = Path(path)
    if not path.is_file():
        raise StoreError(f"{path}: no such file")
    try:
        with xr.open_dataset(path, engine="netcdf4") as ds:
            ds = ds.load()
    except Exception as exc:  # netCDF4/HDF5 raise assorted types for corrupt files
        raise StoreError(f"{path} cannot be read as netCDF ({type(exc).__name__}: {exc})") from None
    found = ds.attrs.get("hardpack_kind")
    if kind is not None and found != kind:
        raise StoreError(f"{path} holds hardpack_kind={found!r}, expected {kind!r}")
    return ds


def load_packing(path, **packing_kwargs) -> Packing:
    """Load and validate a packing written by :func:`save_packing`.

    Parameters
    ----------
    path : str or os.PathLike
        A netCDF file of ``hardpack_kind`` "packing".
    **packing_kwargs
        Passed to :class:`Packing` (e.g. ``allow_overlap``, ``overlap_tol``).

    Returns
    -------
    Packing
        The validated packing.

    Raises
    ------
    StoreError
        If the file is missing, unreadable, not a packing, or holds an invalid packing
        (:func:`load_dataset`, :func:`dataset_to_packing`).
    """
    ds = load_dataset(path, kind="packing")
    return dataset_to_packing(ds, source=str(path), **packing_kwargs)


def load_judged_packing(path, verdict_path) -> tuple[xr.Dataset, Packing, xr.Dataset]:
    """A packing file with the jamming verdict that judges it (``hardpack verify`` output).

    Parameters
    ----------
    path : str or os.PathLike
        The packing file (``hardpack_kind`` "packing").
    verdict_path : str or os.PathLike
        The verdict file (``hardpack_kind`` "jamming") of that packing.

    Returns
    -------
    packing_dataset : xarray.Dataset
        The packing file's dataset.
    packing : Packing
        The validated packing.
    verdict : xarray.Dataset
        The jamming verdict.

    Raises
    ------
    InvalidInputError
        If the verdict's ``source`` attribute names another file than ``path``.
    StoreError
        If either file is missing, unreadable or of the wrong kind, or the packing is invalid.
    """
    ds, verdict = load_dataset(path, kind="packing"), load_dataset(verdict_path, kind="jamming")
    source = verdict.attrs.get("source")
    if source is not None and os.path.normpath(source) != os.path.normpath(str(path)):
        raise InvalidInputError(f"{verdict_path} judges {source}, not {path}")
    return ds, dataset_to_packing(ds, source=str(path)), verdict


def load_judged_packings(packing_paths, verdict_paths, what: str) -> list:
    """:func:`load_judged_packing` for each packing and its verdict, given as two lists in the
    same order; ``what`` names the caller in the message when the lists do not pair up.

    Parameters
    ----------
    packing_paths : sequence of str or os.PathLike
        The packing files.
    verdict_paths : sequence of str or os.PathLike
        Their verdict files, ``verdict_paths[k]`` judging ``packing_paths[k]``.
    what : str
        What the packings are for, e.g. "order map" (starts the error message).

    Returns
    -------
    list of tuple
        One ``(packing_dataset, packing, verdict)`` per packing, in order.

    Raises
    ------
    InvalidInputError
        If there are no packings or not one verdict per packing, or as :func:`load_judged_packing`.
    """
    packing_paths, verdict_paths = list(packing_paths), list(verdict_paths)
    if not packing_paths or len(packing_paths) != len(verdict_paths):
        raise InvalidInputError(
            f"{what}: need one verdict per packing, got {len(packing_paths)} packings and "
            f"{len(verdict_paths)} verdicts")
    return [load_judged_packing(path, verdict) for path, verdict in zip(packing_paths, verdict_paths)]


def _check_members(dsets, names, index) -> None:
    """Refuse an ensemble whose members do not belong together (the message names the files)."""
    seen: dict = {}
    for name in names:
        key = Path(name).resolve() if not name.startswith("dataset ") else name
        if key in seen:
            raise InvalidInputError(f"{name} is given twice ({seen[key]} and {name}); give each file once")
        seen[key] = name
    kinds = {}
    for ds, name in zip(dsets, names):
        kinds.setdefault(ds.attrs.get("hardpack_kind"), []).append(name)
    if None in kinds:
        raise StoreError(f"{', '.join(kinds[None])}: not a hardpack result (no hardpack_kind attribute)")
    if len(kinds) > 1:
        listing = "; ".join(f"{kind}: {', '.join(files)}" for kind, files in kinds.items())
        raise InvalidInputError(f"the files hold different kinds of results ({listing}); "
                                "combine files of one kind only (e.g. only packings)")
    dims = {}
    for ds, name in zip(dsets, names):
        dims.setdefault(ds.attrs.get("d"), []).append(name)
    if len(dims) > 1 and "d" not in index:
        listing = "; ".join(f"d = {d}: {', '.join(files)}" for d, files in dims.items())
        raise InvalidInputError(f"the files are of different dimensions ({listing}); combine one "
                                "dimension at a time, or add d to --index to tabulate them together")
    for attr, default, what in (("shape_kind", "sphere", "particle shapes"), ("boundary", "periodic", "boundaries")):
        groups: dict = {}
        for ds, name in zip(dsets, names):
            groups.setdefault(str(ds.attrs.get(attr, default)), []).append(name)
        if len(groups) > 1 and attr not in index:
            listing = "; ".join(f"{attr} = {k}: {', '.join(files)}" for k, files in groups.items())
            raise InvalidInputError(f"the files hold different {what} ({listing}); combine one kind at a "
                                    f"time, or add {attr} to --index to tabulate them together")
    rows: dict = {}
    for ds, name in zip(dsets, names):
        row = tuple(repr(np.asarray(ds.attrs[k]).tolist()) for k in index)
        if row in rows:
            values = ", ".join(f"{k} = {ds.attrs[k]}" for k in index)
            raise InvalidInputError(f"{rows[row]} and {name} have the same index values ({values}); "
                                    "each sample needs its own (a duplicate run, or index by more "
                                    "attributes)")
        rows[row] = name


def combine_ensemble(sources, index=("seed",), variables=None) -> xr.Dataset:
    """One Dataset over a ``sample`` dimension from results of one kind (paths or Datasets).

    Each ``index`` name (a protocol parameter such as ``seed``, ``N``, ``d``, ``distribution``,
    ``growth_rate``) becomes a coordinate along ``sample`` taken from the file attributes;
    scalar attributes ``N``, ``d``, ``phi`` and any numeric ones named in ``variables`` become
    data variables, with the radius range and mean. Per-particle arrays are stacked along
    ``sample`` only when every member has the same N and d.

    Refused, with the files named: a file given twice, two files with the same index values,
    files of different ``hardpack_kind`` (e.g. a jamming verdict among packings) or without one,
    and files of different dimension d, particle shapes (``shape_kind``) or boundaries
    (``boundary``) unless that attribute is an index.

    Parameters
    ----------
    sources : iterable of str, os.PathLike or xarray.Dataset
        The members, files (loaded with :func:`load_dataset`) or datasets.
    index : sequence of str, default ("seed",)
        Attributes that label the samples; each becomes a coordinate along ``sample``.
    variables : sequence of str, optional
        Further numeric attributes to tabulate as data variables along ``sample``.

    Returns
    -------
    xarray.Dataset
        Dimension ``sample`` with the ``index`` coordinates, the data variables ``N``, ``d``,
        ``phi`` and ``variables`` (where every member has them), ``radius_min``,
        ``radius_max``, ``radius_mean`` (sphere members), the stacked ``position``,
        ``radius``, ``semiaxis``, ``quaternion``, ``angle``, ``lattice`` when all members have
        the same N and d, and the attributes ``hardpack_kind`` = "ensemble" and ``index``.

    Raises
    ------
    InvalidInputError
        If ``sources`` is empty, or the members do not belong together (as listed above).
    StoreError
        If a member is unreadable, has no ``hardpack_kind`` or lacks an ``index`` attribute.
    """
    dsets, names = [], []
    for src in sources:
        ds = load_dataset(src) if not isinstance(src, xr.Dataset) else src
        dsets.append(ds)
        names.append(str(src) if not isinstance(src, xr.Dataset) else f"dataset {len(names)}")
    if not dsets:
        raise InvalidInputError("combine_ensemble needs at least one packing")
    coords, scalars = {}, {}
    for key in index:
        vals = []
        for ds, name in zip(dsets, names):
            if key not in ds.attrs:
                raise StoreError(f"{name} has no attribute {key!r} to index the ensemble by")
            vals.append(ds.attrs[key])
        coords[key] = ("sample", np.asarray(vals))
    _check_members(dsets, names, index)
    for key in ("N", "d", "phi", *(variables or ())):
        if key not in coords and all(key in ds.attrs for ds in dsets):
            scalars[key] = ("sample", np.asarray([ds.attrs[key] for ds in dsets]))
    if all("radius" in ds for ds in dsets):
        scalars["radius_min"] = ("sample", np.array([float(ds["radius"].min()) for ds in dsets]))
        scalars["radius_max"] = ("sample", np.array([float(ds["radius"].max()) for ds in dsets]))
        scalars["radius_mean"] = ("sample", np.array([float(ds["radius"].mean()) for ds in dsets]))
    out = xr.Dataset(scalars, coords=coords)
    shapes = {(ds.sizes.get("particle"), ds.sizes.get("dim")) for ds in dsets}
    if len(shapes) == 1 and None not in next(iter(shapes)):
        for var in ("position", "radius", "semiaxis", "quaternion", "angle", "lattice"):
            if all(var in ds for ds in dsets):
                out[var] = xr.concat([ds[var] for ds in dsets], dim="sample")
    out.attrs["hardpack_kind"] = "ensemble"
    out.attrs["index"] = list(index)
    return out
