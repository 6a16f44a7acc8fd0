"""The validation targets: every published number the report compares with, as data.

``targets.yaml`` (beside this module) lists each target once: its id, the quantity, the published
value (as printed, so that its digits are known), the citation of the published work, the
tolerance with its origin, the kind of row, and the smallest N and number of seeds at which the
tolerance means something. ``targets.schema.yaml`` validates it on every load. A printed table is
one entry whose cells become targets ``<id>-<row>-<column>`` (or ``<id>-<row>`` for a table with
one value column); its special columns are ``N`` (the row applies at exactly that N) and
``error`` (the row's stated tolerance, with ``tolerance: stated``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from decimal import Decimal
from functools import lru_cache
from importlib import resources

import jsonschema
import yaml

from hardpack.errors import InvalidInputError

#: YAML's safe loader in C where PyYAML has libyaml (15x faster on the targets table: 0.016 s against
#: 0.24 s, which every figure job that draws a published value would pay), else in Python
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def _load_yaml(stream):
    return yaml.load(stream, Loader=_YAML_LOADER)

KINDS = ("reproduction", "analytic", "cross-check")
#: table columns that are parameters of a row, not published values
PARAMETER_COLUMNS = ("N", "error")


def ulp(printed: str) -> float:
    """One unit in the last printed digit of ``printed`` ("0.080" -> 0.001, "6.1e-4" -> 1e-5).

    Parameters
    ----------
    printed : str
        A number as printed.

    Returns
    -------
    float
        The unit.
    """
    return float(Decimal(1).scaleb(Decimal(printed).as_tuple().exponent))


@dataclass(frozen=True)
class Target:
    """One published number and the rule by which a reproduced value is judged against it.

    Attributes
    ----------
    id, study, kind, quantity, citation
        Identity and provenance (``kind`` is one of :data:`KINDS`).
    published : float
        The published value (NaN for a fit evaluated by the row, ``published_from``).
    printed : str or None
        The published value as printed, when its digits matter.
    tolerance : float
        Allowed |reproduced - published| before our own uncertainty is added (relative to the
        published value when ``relative``).
    relative : bool
        The tolerance is relative to |published|.
    tolerance_origin, tolerance_note
        Where the tolerance comes from (see ``targets.yaml``) and why.
    single_sample : bool
        The published value is one sample (one packing): the row's uncertainty is our spread over
        samples, sd sqrt(1 + 1/n), instead of our standard error.
    min_n, max_n, min_seeds, min_sizes
        Below min_n particles, above max_n, with fewer seeds or distinct sizes the row is n/a.
    domain : dict
        For parameterised families: the families and width range the claim covers.
    known_deviation : str or None
        Why we are known to differ; the row then fails without failing the gate.
    published_from : str or None
        Name of the published fit in :mod:`hardpack.eos.theory` that gives the published value.
    """

    id: str
    study: str
    kind: str
    quantity: str
    citation: str
    published: float
    tolerance: float
    tolerance_origin: str
    tolerance_note: str
    printed: str | None = None
    relative: bool = False
    single_sample: bool = False
    min_n: int = 1
    max_n: int | None = None
    min_seeds: int = 1
    min_sizes: int = 1
    domain: dict = field(default_factory=dict)
    known_deviation: str | None = None
    published_from: str | None = None

    def absolute_tolerance(self, published: float | None = None) -> float:
        """The tolerance in the units of the quantity (relative ones scaled by |published|).

        Parameters
        ----------
        published : float, optional
            Published value to scale by; the target's own if None (e.g. a value evaluated from a fit).

        Returns
        -------
        float
            The tolerance.
        """
        value = self.published if published is None else published
        return self.tolerance * abs(value) if self.relative else self.tolerance

    def not_applicable(self, n=None, seeds=None, sizes=None) -> str | None:
        """Why a measurement of ``n`` particles, ``seeds`` seeds and ``sizes`` distinct N cannot
        be judged against this target, or None when it can.

        Parameters
        ----------
        n : int, optional
            Particles (checked against min_n and max_n; not checked if None).
        seeds : int, optional
            Seeds (checked against min_seeds; not checked if None).
        sizes : int, optional
            Distinct system sizes (checked against min_sizes; not checked if None).

        Returns
        -------
        str or None
            The first reason, in words, or None.
        """
        if n is not None and n < self.min_n:
            return f"N = {n} is below the N = {self.min_n} at which the tolerance means something"
        if n is not None and self.max_n is not None and n > self.max_n:
            return f"N = {n} is above the N = {self.max_n} the claim is made for"
        if seeds is not None and seeds < self.min_seeds:
            return f"{seeds} seed(s); the tolerance needs at least {self.min_seeds}"
        if sizes is not None and sizes < self.min_sizes:
            return f"{sizes} system size(s); the extrapolation needs at least {self.min_sizes}"
        return None

    def covers(self, family: str, width: float) -> bool:
        """True when the claim covers the distribution ``family`` at width ``width``.

        Parameters
        ----------
        family : str
            Distribution family (compared with ``domain["families"]``; any if absent).
        width : float
            Width of the distribution (compared with ``width_min``, ``width_max`` and
            ``width_min_exclusive`` of ``domain``, where present).

        Returns
        -------
        bool
            Whether the target's domain holds the family and width.
        """
        d = self.domain
        return (family in d.get("families", [family])
                and width >= d.get("width_min", -math.inf) and width <= d.get("width_max", math.inf)
                and width > d.get("width_min_exclusive", -math.inf))


def _schema():
    text = resources.files("hardpack.validation").joinpath("targets.schema.yaml").read_text()
    return _load_yaml(text)


def _value(printed) -> tuple[float, str | None]:
    if isinstance(printed, str):
        return float(printed), printed
    return float(printed), None


def _table_targets(entry: dict) -> list[Target]:
    """The cells of a printed table as targets."""
    table = entry["table"]
    columns, key = table["columns"], table["key"]
    if key not in columns:
        raise InvalidInputError(f"validation target {entry['id']}: key column {key!r} is not among {columns}")
    values = [c for c in columns if c != key and c not in PARAMETER_COLUMNS]
    deviations = dict(entry.get("known_deviations", {}))
    base = {k: v for k, v in entry.items() if k not in ("table", "known_deviations", "id", "tolerance", "quantity")}
    out = []
    for line in table["rows"]:
        cells = line.split()
        if len(cells) != len(columns):
            raise InvalidInputError(f"validation target {entry['id']}: table row {line!r} has {len(cells)} "
                                    f"cells for the columns {columns}")
        row = dict(zip(columns, cells))
        key_value = row[key]
        label = f"{key}{key_value}" if _is_number(key_value) else key_value
        for column in values:
            if row[column] == "-":
                continue
            suffix = f"{label}-{column}" if len(values) > 1 else label
            published, printed = _value(row[column])
            if entry["tolerance"] == "printed-digits":
                tolerance = 0.5 * ulp(printed)
            elif entry["tolerance"] == "stated":
                tolerance = float(row["error"])
            else:
                tolerance = float(entry["tolerance"])
            extra = {}
            if "N" in row and key != "N":
                extra.update(min_n=int(row["N"]), max_n=int(row["N"]))
            if key == "N":
                extra.update(min_n=int(key_value), max_n=int(key_value))
            out.append(_target({**base, **extra}, id=f"{entry['id']}-{suffix.lower()}",
                               quantity=f"{entry['quantity']}: {key} = {key_value}"
                               + (f", {column}" if len(values) > 1 else ""),
                               published=published, printed=printed, tolerance=tolerance,
                               known_deviation=deviations.pop(suffix, None)))
    if deviations:
        raise InvalidInputError(f"validation target {entry['id']}: known_deviations name no cell: "
                                f"{sorted(deviations)}")
    return out


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _target(fields: dict, **overrides) -> Target:
    merged = {**fields, **overrides}
    names = {f for f in Target.__dataclass_fields__}
    return Target(**{k: v for k, v in merged.items() if k in names})


def _scalar_target(entry: dict) -> Target:
    if "published_from" in entry:
        published, printed = math.nan, None
    else:
        published, printed = _value(entry["published"])
    tolerance = 0.5 * ulp(printed) if entry["tolerance"] == "printed-digits" else float(entry["tolerance"])
    return _target(entry, published=published, printed=printed, tolerance=tolerance)


def parse_targets(document: dict) -> dict[str, Target]:
    """Targets by id from a parsed ``targets.yaml`` document (validated against the schema).

    Parameters
    ----------
    document : dict
        The parsed YAML document.

    Returns
    -------
    dict of str to Target
        Target id -> target.

    Raises
    ------
    InvalidInputError
        If the document does not follow the schema, an id repeats, or a known deviation names
        no table cell.
    """
    try:
        jsonschema.validate(document, _schema())
    except jsonschema.ValidationError as exc:
        where = "/".join(str(p) for p in exc.absolute_path) or "the top level"
        raise InvalidInputError(f"validation targets: {exc.message} (at {where})") from None
    out: dict[str, Target] = {}
    for entry in document["targets"]:
        for target in _table_targets(entry) if "table" in entry else [_scalar_target(entry)]:
            if target.id in out:
                raise InvalidInputError(f"validation targets: id {target.id!r} appears twice")
            out[target.id] = target
    return out


@lru_cache(maxsize=1)
def _packaged() -> dict[str, Target]:
    text = resources.files("hardpack.validation").joinpath("targets.yaml").read_text()
    return parse_targets(_load_yaml(text))


def load_targets(path=None) -> dict[str, Target]:
    """The validation targets by id: the packaged table, or the YAML file at ``path``.

    Parameters
    ----------
    path : str or os.PathLike, optional
        A targets YAML file in the schema of ``targets.schema.yaml``; default the packaged
        ``targets.yaml``.

    Returns
    -------
    dict of str to Target
        The targets by id.

    Raises
    ------
    InvalidInputError
        If the document does not follow the schema, an id repeats, or a known deviation names
        no table cell (:func:`parse_targets`).
    OSError
        If ``path`` cannot be opened.
    """
    if path is None:
        return dict(_packaged())
    with open(path) as fh:
        return parse_targets(_load_yaml(fh))


def target(target_id: str, targets: dict[str, Target] | None = None) -> Target:
    """One target by id (from ``targets``, default the packaged table).

    Parameters
    ----------
    target_id : str
        The id.
    targets : dict of str to Target, optional
        The table.

    Returns
    -------
    Target
        The target.

    Raises
    ------
    InvalidInputError
        For an unknown id.
    """
    table = _packaged() if targets is None else targets
    try:
        return table[target_id]
    except KeyError:
        raise InvalidInputError(f"no validation target {target_id!r}") from None


__all__ = ["KINDS", "Target", "load_targets", "parse_targets", "target", "ulp"]
