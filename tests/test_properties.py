"""Property-based tests (hypothesis): the packing model, the netCDF store and the config schema.

- Packing: random valid packings in random (sheared) lattices keep their arrays bit for bit, their
  volume fraction is unchanged by wrapping the centres into the cell and by a unimodular change of
  lattice basis (the same periodic packing), and overlapping or non-finite inputs are refused.
- Shapes and boundaries: random spheres or ellipsoids (2D, 3D) in periodic cells, between hard
  walls on random axes or in a spherical container are valid, keep phi when wrapped along the
  periodic axes, and come back bit for bit from the store; quaternions within round-off of unit
  are normalised once and then kept bit for bit.
- Store: save/load keeps every array bit for bit (and its dtype) and the attributes.
- Config schema: a random unknown key anywhere in config/smoke.yaml, or a value of the wrong type
  at any leaf, is refused.
"""

import copy
import itertools
import tempfile
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from hardpack.errors import InvalidInputError
from hardpack.geometry import Ellipsoids, HardWalls, SphericalContainer
from hardpack.geometry.packing import Packing
from hardpack.io import load_dataset, load_packing, save_packing

ROOT = Path(__file__).resolve().parents[1]
FAST = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------- random valid packings
def _min_image_distances(x, lattice, periodic=None):
    """Smallest distance of every pair (i, j), and of every particle to its own images, over the
    lattice shifts n in {-2..2}^d (enough for the mildly sheared cells drawn below); n_k = 0 along
    the axes that are not ``periodic``."""
    d = lattice.shape[0]
    periodic = np.ones(d, bool) if periodic is None else periodic
    shifts = np.array([n for n in itertools.product(range(-2, 3), repeat=d)
                       if not np.any(np.array(n)[~periodic])], float) @ lattice.T
    sep = x[None, :, None, :] - x[:, None, None, :] + shifts[None, None, :, :]
    dist = np.linalg.norm(sep, axis=-1)
    zero = np.all(shifts == 0, axis=1)
    for i in range(len(x)):
        dist[i, i, zero] = np.inf
    return dist.min(axis=2)


@st.composite
def packings(draw, max_n=8):
    d = draw(st.integers(1, 4))
    n = draw(st.integers(1, max_n))
    unit = st.floats(0.0, 1.0, exclude_max=True, allow_nan=False)
    diag = np.array(draw(st.lists(st.floats(1.0, 3.0), min_size=d, max_size=d)))
    lower = np.array(draw(st.lists(st.floats(-0.3, 0.3), min_size=d * d, max_size=d * d))).reshape(d, d)
    lattice = np.diag(diag) + np.tril(lower, -1) * diag[None, :]
    frac = np.array(draw(st.lists(st.lists(unit, min_size=d, max_size=d), min_size=n, max_size=n)))
    x = frac @ lattice.T
    dist = _min_image_distances(x, lattice)
    cap = 0.49 * dist.min()
    assume(cap > 1e-3)
    factors = np.array(draw(st.lists(st.floats(0.05, 1.0), min_size=n, max_size=n)))
    return x, cap * factors, lattice


@st.composite
def unimodular(draw, d):
    """An integer matrix of determinant +-1: a product of elementary shears and a sign flip."""
    u = np.eye(d, dtype=np.int64)
    if d == 1:
        return u * draw(st.sampled_from([1, -1]))
    for _ in range(draw(st.integers(1, 4))):
        i, j = draw(st.tuples(st.integers(0, d - 1), st.integers(0, d - 1)).filter(lambda t: t[0] != t[1]))
        e = np.eye(d, dtype=np.int64)
        e[i, j] = draw(st.integers(-2, 2))
        u = u @ e
    if draw(st.booleans()):
        u[:, 0] *= -1
    return u


@FAST
@given(packings())
def test_arrays_round_trip_bit_for_bit(case):
    x, radii, lattice = case
    p = Packing(x, radii, lattice)
    assert np.array_equal(p.positions, x) and np.array_equal(p.radii, radii)
    assert np.array_equal(p.lattice, lattice)


@FAST
@given(packings(), st.data())
def test_phi_is_invariant_under_wrapping_and_change_of_basis(case, data):
    x, radii, lattice = case
    p = Packing(x, radii, lattice)
    n, d = x.shape
    images = np.array(data.draw(st.lists(st.integers(-3, 3), min_size=n * d, max_size=n * d))).reshape(n, d)
    shifted = Packing(x + images @ lattice.T, radii, lattice)  # centres moved by lattice vectors
    wrapped = shifted.wrapped()
    assert wrapped.phi == p.phi
    assert np.all((wrapped.fractional() >= 0) & (wrapped.fractional() < 1))
    u = data.draw(unimodular(p.dim))
    other = Packing(x, radii, lattice @ u)  # the same periodic packing: still valid
    assert other.phi == pytest.approx(p.phi, rel=1e-12)
    assert other.wrapped().phi == pytest.approx(p.phi, rel=1e-12)


@FAST
@given(packings(max_n=6), st.floats(1e-6, 0.9), st.data())
def test_overlaps_are_refused(case, depth, data):
    x, radii, lattice = case
    n, d = x.shape
    assume(n >= 2)
    direction = np.array(data.draw(st.lists(st.floats(-1, 1), min_size=d, max_size=d)))
    assume(np.linalg.norm(direction) > 0.1)
    x = x.copy()
    contact = radii[0] + radii[1]
    x[1] = x[0] + direction / np.linalg.norm(direction) * contact * (1 - depth)
    with pytest.raises(InvalidInputError, match="particles overlap beyond the tolerance"):
        Packing(x, radii, lattice)


@FAST
@given(packings(), st.sampled_from(["positions", "radii", "lattice"]), st.sampled_from([np.nan, np.inf, -np.inf]),
       st.data())
def test_non_finite_inputs_are_refused(case, name, bad, data):
    arrays = dict(zip(("positions", "radii", "lattice"), (a.copy() for a in case)))
    target = arrays[name].reshape(-1)
    target[data.draw(st.integers(0, target.size - 1))] = bad
    with pytest.raises(InvalidInputError, match="non-finite value"):
        Packing(**arrays)


@st.composite
def shaped_packings(draw, max_n=6):
    """Spheres or ellipsoids (d = 2, 3) in a periodic cube, between hard walls on a random set of
    axes, or in a spherical container touching the box faces; bounding spheres disjoint and inside."""
    d = draw(st.sampled_from([2, 3]))
    n = draw(st.integers(1, max_n))
    box = draw(st.floats(3.0, 8.0))
    kind = draw(st.sampled_from(["periodic", "walls", "container"]))
    unit = st.floats(0.0, 1.0, exclude_max=True, allow_nan=False)
    x = box * np.array(draw(st.lists(st.lists(unit, min_size=d, max_size=d), min_size=n, max_size=n)))
    lattice = box * np.eye(d)
    if kind == "periodic":
        boundary, periodic, room = "periodic", np.ones(d, bool), np.full(n, np.inf)
    elif kind == "walls":
        axes = draw(st.lists(st.integers(0, d - 1), min_size=1, max_size=d, unique=True))
        boundary = HardWalls(axes)
        periodic = boundary.periodic_axes(d)
        room = np.minimum(x[:, ~periodic], box - x[:, ~periodic]).min(axis=1)
    else:
        boundary, periodic = SphericalContainer(np.full(d, box / 2), box / 2), np.zeros(d, bool)
        room = box / 2 - np.linalg.norm(x - box / 2, axis=1)
    dist = _min_image_distances(x, lattice, periodic)
    bound = np.minimum(0.49 * dist.min(axis=1), 0.99 * room)
    assume(bound.min() > 1e-3)
    factors = np.array(draw(st.lists(st.floats(0.05, 1.0), min_size=n * d, max_size=n * d))).reshape(n, d)
    if draw(st.booleans()):
        return Packing(x, bound * factors[:, 0], lattice, boundary=boundary)
    semiaxes = bound[:, None] * factors
    if d == 2:
        orient = np.array(draw(st.lists(st.floats(-10, 10), min_size=n, max_size=n)))
    else:
        q = np.array(draw(st.lists(st.floats(-1, 1), min_size=4 * n, max_size=4 * n))).reshape(n, 4)
        assume(np.linalg.norm(q, axis=1).min() > 0.1)
        orient = q / np.linalg.norm(q, axis=1)[:, None]
    return Packing(x, lattice=lattice, shape=Ellipsoids(semiaxes, orient), boundary=boundary)


@FAST
@given(shaped_packings(), st.data())
def test_shaped_packings_keep_phi_when_wrapped_along_periodic_axes(p, data):
    n, d = p.n_particles, p.dim
    periodic = p.boundary.periodic_axes(d)
    images = np.array(data.draw(st.lists(st.integers(-3, 3), min_size=n * d, max_size=n * d))).reshape(n, d)
    shifted = p.replace(positions=p.positions + (images * periodic) @ p.lattice.T)
    wrapped = shifted.wrapped()
    assert wrapped.phi == p.phi
    s = wrapped.fractional()[:, periodic]
    assert np.all((s >= 0) & (s < 1))
    assert np.array_equal(wrapped.positions[:, ~periodic], p.positions[:, ~periodic])


@settings(max_examples=25, deadline=None)
@given(shaped_packings())
def test_shapes_and_boundaries_round_trip_bit_exact(p):
    with tempfile.TemporaryDirectory() as folder:
        q = load_packing(save_packing(p, Path(folder) / "p.nc"))
    assert q.boundary == p.boundary and q.shape.kind == p.shape.kind
    arrays = ("positions", "lattice") + (("radii",) if p.shape.kind == "sphere" else ())
    for a, b in [(getattr(p, k), getattr(q, k)) for k in arrays] + (
            [] if p.shape.kind == "sphere" else
            [(p.shape.semiaxes, q.shape.semiaxes), (p.shape.orientations, q.shape.orientations)]):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    assert q.phi == p.phi


@FAST
@given(st.lists(st.floats(-1, 1), min_size=4, max_size=4), st.floats(-0.99e-10, 0.99e-10))
def test_quaternions_near_unit_are_normalised_once(q, excess):
    q = np.array(q)
    assume(np.linalg.norm(q) > 0.1)
    w = q / np.linalg.norm(q) * (1 + excess)
    once = Ellipsoids(np.ones((1, 3)), w[None]).orientations
    # unit to round-off: quaternions within 8 eps of unit norm are kept as given (so that a
    # second construction changes nothing), the others divided by their norm
    assert abs(np.linalg.norm(once) - 1) <= 8 * np.finfo(float).eps
    assert np.array_equal(Ellipsoids(np.ones((1, 3)), once).orientations, once)


# ---------------------------------------------------------------- netCDF store
attr_keys = st.from_regex(r"x_[a-z][a-z0-9_]{0,12}", fullmatch=True)
attr_values = st.one_of(
    st.integers(-2**63, 2**63 - 1),
    st.floats(allow_nan=False),
    st.text(st.characters(min_codepoint=32, max_codepoint=0x2FFF, exclude_categories=("Cs",)), max_size=30),
    st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=1, max_size=5),
)


@settings(max_examples=25, deadline=None)
@given(packings(), st.dictionaries(attr_keys, attr_values, max_size=6), st.booleans())
def test_store_round_trip_is_bit_exact(case, attrs, with_species):
    x, radii, lattice = case
    species = np.arange(len(x)) % 3 if with_species else None
    p = Packing(x, radii, lattice, species=species)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "p.nc"
        save_packing(p, path, attrs=attrs)
        q = load_packing(path)
        stored = load_dataset(path).attrs
    for name in ("positions", "radii", "lattice"):
        a, b = getattr(p, name), getattr(q, name)
        assert a.dtype == b.dtype and np.array_equal(a, b)
    assert (q.species is None) == (species is None)
    if species is not None:
        assert np.array_equal(q.species, p.species)
    for key, value in attrs.items():
        if isinstance(value, list):
            assert np.array_equal(np.atleast_1d(stored[key]), np.asarray(value))
        elif isinstance(value, float):
            assert np.float64(stored[key]).tobytes() == np.float64(value).tobytes()
        else:
            assert stored[key] == value
    assert stored["N"] == len(x) and stored["d"] == x.shape[1] and stored["phi"] == p.phi


# ---------------------------------------------------------------- config schema
SCHEMA = yaml.safe_load((ROOT / "workflow/schemas/config.schema.yaml").read_text())
SMOKE = yaml.safe_load((ROOT / "config/smoke.yaml").read_text())
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)


def _nodes(node, path=()):
    """Every (path, value) in the config tree."""
    yield path, node
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _nodes(value, path + (key,))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _nodes(value, path + (i,))


def _get(tree, path):
    for key in path:
        tree = tree[key]
    return tree


DICTS = [p for p, v in _nodes(SMOKE) if isinstance(v, dict)]
LEAVES = [p for p, v in _nodes(SMOKE) if not isinstance(v, (dict, list))] + \
         [p for p, v in _nodes(SMOKE) if isinstance(v, list) and p]


def _kind(value):
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, (int, float)):
        return "number"
    return {str: "string", list: "list", dict: "dict"}[type(value)]


WRONG = {"number": "a string", "string": 3, "bool": "yes", "list": {"a": 1}, "dict": [1]}
OTHERS = [True, "text", 2.5, [1, 2], {"k": 1}]


def test_the_smoke_config_is_valid():
    assert VALIDATOR.is_valid(SMOKE) and len(DICTS) > 10 and len(LEAVES) > 30


@FAST
@given(st.sampled_from(DICTS), st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,15}", fullmatch=True),
       st.sampled_from(OTHERS))
def test_unknown_keys_are_refused(path, key, value):
    cfg = copy.deepcopy(SMOKE)
    node = _get(cfg, path)
    assume(key not in node)
    node[key] = value
    assert not VALIDATOR.is_valid(cfg), f"{'.'.join(map(str, path + (key,)))} = {value!r} was accepted"


@FAST
@given(st.sampled_from(LEAVES), st.sampled_from(OTHERS))
def test_wrong_types_are_refused(path, value):
    cfg = copy.deepcopy(SMOKE)
    original = _get(cfg, path)
    assume(_kind(value) != _kind(original))
    _get(cfg, path[:-1])[path[-1]] = value
    assert not VALIDATOR.is_valid(cfg), f"{'.'.join(map(str, path))} = {value!r} was accepted"
