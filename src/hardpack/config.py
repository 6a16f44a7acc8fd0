"""Checks of a workflow config: its JSON schema, and cross references the schema cannot express.

The workflow (``workflow/rules/common.smk``) validates a config against
``workflow/schemas/config.schema.yaml`` (keys, types, ranges) with :func:`validate_schema` and
then calls :func:`check_config`, which refuses sections that contradict each other: a study that
names an ensemble or seeds that do not exist, a container study whose largest container has no
core, and so on. Every message names the key to fix. The checks live in the library so that they
are tested without building the DAG.
"""

from __future__ import annotations

from hardpack.distributions import from_spec
from hardpack.errors import InvalidInputError

__all__ = ["check_config", "validate_schema"]


def validate_schema(config: dict, schema_path) -> None:
    """Validate a workflow config against its JSON schema (draft 2020-12), filling in the
    schema's defaults, as ``snakemake.utils.validate`` does.

    Every Snakemake process of a run (one or two per cluster job) parses the workflow and so
    validates its config; Snakemake's own validator reads the schema with a pure-Python YAML
    parser (0.45 s), this one with libyaml's (0.01 s).

    Parameters
    ----------
    config : dict
        The workflow config; defaults of the schema are set in place.
    schema_path : str or path-like
        The schema, YAML or JSON.

    Raises
    ------
    InvalidInputError
        When the config breaks the schema; the message names the key and what is wrong.
    """
    import jsonschema
    import yaml

    with open(schema_path) as fh:
        schema = yaml.load(fh, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    base = jsonschema.Draft202012Validator
    check_properties = base.VALIDATORS["properties"]

    def properties_with_defaults(validator, properties, instance, subschema):
        if isinstance(instance, dict):
            for key, spec in properties.items():
                if isinstance(spec, dict) and "default" in spec:
                    instance.setdefault(key, spec["default"])
        yield from check_properties(validator, properties, instance, subschema)

    validator = jsonschema.validators.extend(base, {"properties": properties_with_defaults})(schema)
    error = jsonschema.exceptions.best_match(validator.iter_errors(config))
    if error is not None:
        where = ".".join(str(k) for k in error.absolute_path) or "the top level"
        _refuse(f"config: {error.message} (at {where}; the keys and their types are in {schema_path})")


def check_config(config: dict) -> None:
    """Refuse a schema-valid workflow config whose sections contradict each other.

    Parameters
    ----------
    config : dict
        The workflow config, already validated against the JSON schema (missing optional
        sections are skipped).

    Raises
    ------
    InvalidInputError
        On the first contradiction found; the message starts with ``config:`` and names the key.
    """
    ensembles = config["ensembles"]
    _check_ensembles(ensembles, config)
    _check_slp(ensembles, config.get("slp", {}))
    _check_one_run_per_dimension("ls_densest", config.get("ls_densest"))
    _check_freeenergy(ensembles, config.get("freeenergy"))
    _check_glass(config.get("glass"), config.get("microsegregated"))
    _check_ellipsoids(config.get("ellipsoids"))
    _check_crystal_search((config.get("ellipsoid_crystals") or {}).get("search"))
    _check_containers(ensembles, config.get("containers"), config.get("ellipsoid_containers"))


def _refuse(message: str):
    raise InvalidInputError(f"config: {message}")


def _check_distribution(where: str, spec: dict) -> None:
    try:
        from_spec(spec)
    except ValueError as exc:
        _refuse(f"{where}.distribution: {exc}")


def _check_ensembles(ensembles: dict, config: dict) -> None:
    for name, ens in ensembles.items():
        _check_distribution(f"ensembles.{name}", ens["distribution"])
    rates = config.get("rates")
    if rates and rates["ensemble"] not in ensembles:
        _refuse(f"rates.ensemble {rates['ensemble']!r} is not one of the ensembles {sorted(ensembles)}")


def _check_one_run_per_dimension(where: str, section: dict | None) -> None:
    if section and len({run["d"] for run in section["runs"]}) != len(section["runs"]):
        _refuse(f"{where}.runs lists a dimension twice")


def _check_slp(ensembles: dict, slp: dict) -> None:
    densest, mrj, diluted = slp.get("densest"), slp.get("mrj"), slp.get("diluted")
    _check_one_run_per_dimension("slp.densest", densest)
    if mrj:
        for name in mrj["ensembles"]:
            if name not in ensembles:
                _refuse(f"slp.mrj.ensembles names {name!r}, which is not an ensemble")
        for name, spec in mrj.get("systems", {}).items():
            if name in ensembles:
                _refuse(f"slp.mrj.systems.{name} has the name of an ensemble; rename it")
            if "distribution" in spec:
                _check_distribution(f"slp.mrj.systems.{name}", spec["distribution"])
    if diluted:
        if not mrj or diluted["ensemble"] not in mrj["ensembles"]:
            _refuse(f"slp.diluted.ensemble {diluted['ensemble']!r} must be one of slp.mrj.ensembles "
                    "(its SLP MRJ packings are the starts)")
        missing = set(diluted["seeds"]) - set(ensembles[diluted["ensemble"]]["seeds"])
        if missing:
            _refuse(f"slp.diluted.seeds {sorted(missing)} are not seeds of ensemble {diluted['ensemble']!r}")


def _check_freeenergy(ensembles: dict, freeenergy: dict | None) -> None:
    if not freeenergy:
        return
    simplex = freeenergy["simplex"]
    if simplex["ensemble"] not in ensembles:
        _refuse(f"freeenergy.simplex.ensemble {simplex['ensemble']!r} is not one of the ensembles "
                f"{sorted(ensembles)}")
    missing = set(simplex["seeds"]) - set(ensembles[simplex["ensemble"]]["seeds"])
    if missing:
        _refuse(f"freeenergy.simplex.seeds {sorted(missing)} are not seeds of ensemble "
                f"{simplex['ensemble']!r} (its LS packings are the inputs)")


def _check_glass(glass: dict | None, microseg: dict | None) -> None:
    if glass:
        if glass["N"] % 2:
            _refuse(f"glass.N = {glass['N']} must be even (the triangular crystal has 2 disks per cell)")
        if not max(glass["snapshots"]) < glass["phi_end"]:
            _refuse("glass.phi_end must be above every glass.snapshots density")
        dx = glass["composition"]["dx"]
        if not (0 < glass["x_large"] - dx and glass["x_large"] + dx < 1):
            _refuse("glass.x_large -+ glass.composition.dx must stay in (0, 1)")
        slow = glass.get("slow")
        if slow:
            if not slow["rate"] < min(glass["rates"]):
                _refuse(f"glass.slow.rate = {slow['rate']:g} must be below every glass.rates (it continues "
                        f"the slowest of them, {min(glass['rates']):g})")
            if slow["from_phi"] not in glass["snapshots"]:
                _refuse(f"glass.slow.from_phi = {slow['from_phi']:g} must be one of glass.snapshots "
                        f"{sorted(glass['snapshots'])} (the slow branch starts from that snapshot)")
        relaxation = glass.get("relaxation")
        if relaxation and relaxation["phi"] not in glass["snapshots"]:
            _refuse(f"glass.relaxation.phi = {relaxation['phi']:g} must be one of glass.snapshots "
                    f"{sorted(glass['snapshots'])} (the relaxation starts from each rate's snapshot there)")
        separated = glass.get("separated")
        if separated and not separated["phi_end"] < separated["phi"]:
            _refuse("glass.separated.phi_end must lie below glass.separated.phi (the crystal is decompressed)")
        crystal = glass["mono"].get("crystal_bcmd")
        if crystal and not max(crystal["phis"]) < glass["mono"]["crystal_phi"]:
            _refuse("glass.mono.crystal_bcmd.phis must lie below glass.mono.crystal_phi (the crystal is "
                    "expanded to each of them)")
    if microseg:
        rows, cols = microseg["shape"]
        if rows % 2:
            _refuse(f"microsegregated.shape rows = {rows} must be even (the triangular crystal)")
        if microseg["window"][0] > rows or microseg["window"][1] > cols:
            _refuse("microsegregated.window must fit microsegregated.shape")
        if microseg["packings"] > microseg["label_realisations"]:
            _refuse("microsegregated.packings must not exceed label_realisations (one packing per label "
                    "realisation)")


def _check_ellipsoids(ellipsoids: dict | None) -> None:
    """The M&M system and the near-sphere systems name ellipsoid families."""
    if not ellipsoids:
        return
    families = ellipsoids["families"]
    if "mm" in ellipsoids and ellipsoids["mm"]["family"] not in families:
        _refuse(f"ellipsoids.mm.family {ellipsoids['mm']['family']!r} is not one of ellipsoids.families "
                f"{sorted(families)}")
    unknown = set(ellipsoids.get("near_sphere", {}).get("families", [])) - set(families)
    if unknown:
        _refuse(f"ellipsoids.near_sphere.families {sorted(unknown)} are not ellipsoids.families {sorted(families)}")


def _check_crystal_search(search: dict | None) -> None:
    if search and any(alpha == 1 for alpha in search["alphas"]):
        _refuse("ellipsoid_crystals.search.alphas contains 1 (spheres): a sphere's collision with its own "
                "periodic image cannot be resolved in a cell of one particle; give aspect ratios other than 1")


def _check_containers(ensembles: dict, containers: dict | None, ellipsoid_containers: dict | None) -> None:
    """The window study reads a 3D LS ensemble; the largest container (of spheres and of
    ellipsoids) has a core; the fit has points."""
    if containers:
        windows = containers["windows"]
        ens = ensembles.get(windows["ensemble"])
        if ens is None or ens["d"] != 3 or ens["distribution"]["kind"] != "monodisperse":
            _refuse(f"containers.windows.ensemble {windows['ensemble']!r} must be a monodisperse 3D ensemble "
                    "(its LS packings are the periodic packings of Fig. 7.3)")
        _check_core("containers", containers)
        fitted = [n for n in containers["N"] if n >= containers["fit_min_n"]]
        if len(fitted) < 2 or len(fitted) * len(containers["seeds"]) < 3:
            _refuse("containers.fit_min_n leaves fewer than 2 container sizes or 3 packings for the Eq. 7.2 fit")
        if not windows["fit_min_diameter"] >= windows["min_diameter"]:
            _refuse("containers.windows.fit_min_diameter must be >= min_diameter")
    if ellipsoid_containers:
        _check_core("ellipsoid_containers", ellipsoid_containers)


def _check_core(key: str, section: dict) -> None:
    largest = max(section["N"])
    if not section["core_margin"] < largest ** (1 / 3):
        _refuse(f"{key}.core_margin = {section['core_margin']} a leaves no core in the largest container "
                f"(N = {largest}, R > N^(1/3) a): lower it")
