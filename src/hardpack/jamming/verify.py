"""verify(packing): the full jamming verdict of a periodic sphere packing.

Steps (Donev dissertation ch. 4, seeds/000_chapters/ch04-05.txt):
1. contact network within the relative gap ``delta`` (Eq. 4.5), all periodic images;
2. local test and iterative rattler removal (LP 4.15, Alg. 13 step 4) -- always run, since
   the other tests need a rattler-free packing;
3. collective test (strain fixed) and strict test (strain with Tr eps <= 0), either with
   Algorithm 13 (``method="ideal"``: exact binary verdict for packings with tiny gaps) or
   Algorithm 14 (``method="sequential"``: random loading that moves the packing, for
   finite-rate packings with gaps; the verdict thresholds the mean displacement). The
   strict test starts from the collectively jammed backbone when there is one;
4. self-stress forces, contact number, isostaticity and pressure of the backbone
   (:mod:`hardpack.jamming.forces`).
"""

from __future__ import annotations

import time

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.jamming.contacts import check_delta, contact_network
from hardpack.jamming.forces import self_stress, statics
from hardpack.jamming.ideal import ideal_test
from hardpack.jamming.rattlers import remove_rattlers
from hardpack.jamming.result import CATEGORIES, JammingResult
from hardpack.jamming.sequential import sequential_test

METHODS = ("ideal", "sequential")
DEFAULT_DELTA = 1e-6


def _positive(name: str, value, upper: float | None = None) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(value) or value <= 0 or (upper is not None and value >= upper):
        bound = f" and below {upper:g}" if upper is not None else ""
        raise InvalidInputError(f"{name} must be a positive finite number{bound}, got {value!r}")
    return value


def _check_tests(tests) -> tuple[str, ...]:
    if isinstance(tests, str):
        tests = (tests,)
    tests = tuple(tests)
    unknown = [t for t in tests if t not in CATEGORIES]
    if unknown or not tests:
        raise InvalidInputError(
            f"unknown jamming test(s) {unknown or tests!r}; choose from {CATEGORIES}"
        )
    return tests


def verify(
    packing: Packing,
    delta: float = DEFAULT_DELTA,
    tests=CATEGORIES,
    seed: int = 0,
    *,
    method: str = "ideal",
    dr_large: float | None = None,
    box: float | None = None,
    threshold: float = 1e-3,
    n_loads: int = 3,
    max_steps: int = 3,
    beta: float = 0.01,
    md_pressure: float | None = None,
    contact_delta: float | None = None,
) -> JammingResult:
    """Classify ``packing`` as locally / collectively / strictly jammed (see the module docstring).

    Parameters
    ----------
    delta : relative gap tolerance for contacts, 0 < delta < 1.
    tests : any of "local", "collective", "strict" (local always runs: the others need it).
    seed : seed of the random loads (results are reproducible for a given seed).
    method : "ideal" (Algorithm 13) or "sequential" (Algorithm 14).
    dr_large : displacement (absolute length) above which a particle counts as displaced in
        the ideal test and the local test; default delta times the mean diameter
        (Alg. 13 step 2, "delta D ~ dr_large").
    box : bound on each displacement component in the LPs; default the mean diameter.
    threshold, n_loads, max_steps, beta : sequential test only (mean displacement / D above
        which the packing is called unjammed; loads; LPs per load direction; step size / D
        below which a loading sequence stops).
    md_pressure : reduced pressure PV/(NkT) measured by the generator, compared with the
        free-volume pressure from the forces.
    contact_delta : gap tolerance of the contacts counted for Z, isostaticity and forces with
        ``method="sequential"``, whose ``delta`` (0.01-1, Donev L1729-L1738) includes near
        neighbours on purpose; default min(delta, 1e-6). The ideal method uses ``delta``.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError(
            f"verify expects a hardpack Packing, got {type(packing).__name__}"
        )
    delta = check_delta(delta)
    tests = _check_tests(tests)
    if method not in METHODS:
        raise InvalidInputError(f"method must be one of {METHODS}, got {method!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError(f"seed must be a non-negative integer, got {seed!r}")
    diameter = 2.0 * float(packing.radii.mean())
    dr_large = delta * diameter if dr_large is None else _positive("dr_large", dr_large)
    box = diameter if box is None else _positive("box", box)
    threshold = _positive("threshold", threshold)
    beta = _positive("beta", beta)
    for name, value in (("n_loads", n_loads), ("max_steps", max_steps)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise InvalidInputError(f"{name} must be a positive integer, got {value!r}")
    if md_pressure is not None:
        md_pressure = _positive("md_pressure", md_pressure)
    if dr_large >= box:
        raise InvalidInputError(
            f"dr_large = {dr_large:g} must be smaller than the LP box {box:g}, otherwise no "
            "displacement can ever count as unjamming"
        )

    rng = np.random.default_rng(int(seed))
    seconds = {}
    t0 = time.perf_counter()
    net = contact_network(packing, delta)
    seconds["contacts"] = time.perf_counter() - t0
    n = packing.n_particles

    t0 = time.perf_counter()
    local_active, escape = remove_rattlers(
        net, np.ones(n, dtype=bool), dr_large=dr_large, box=box, rng=rng
    )
    seconds["local"] = time.perf_counter() - t0

    collective = strict = None
    common = {"box": box, "rng": rng}
    if method == "ideal":
        if "collective" in tests:
            collective = ideal_test(net, local_active, strict=False, dr_large=dr_large, **common)
            seconds["collective"] = collective.seconds
        if "strict" in tests:
            start = collective.backbone if collective is not None and collective.jammed else local_active
            strict = ideal_test(net, start, strict=True, dr_large=dr_large, **common)
            seconds["strict"] = strict.seconds
        backbone = collective.backbone if collective is not None and collective.jammed else local_active
    else:
        kwargs = {"rattlers": ~local_active, "threshold": threshold, "beta": beta,
                  "n_loads": n_loads, "max_steps": max_steps, **common}
        if "collective" in tests:
            collective = sequential_test(packing, delta, strict=False, **kwargs)
            seconds["collective"] = collective.seconds
        if "strict" in tests:
            strict = sequential_test(packing, delta, strict=True, **kwargs)
            seconds["strict"] = strict.seconds
        contact_delta = min(delta, DEFAULT_DELTA) if contact_delta is None else check_delta(contact_delta)
        net = contact_network(packing, contact_delta)
        backbone, _ = remove_rattlers(
            net, np.ones(n, dtype=bool), dr_large=contact_delta * diameter, box=box, rng=rng
        )

    t0 = time.perf_counter()
    forces = self_stress(net, backbone)
    stat = statics(net, backbone, forces, packing.volume)
    seconds["forces"] = time.perf_counter() - t0

    sequential = method == "sequential"
    params = {
        "method": method, "delta": delta, "dr_large": dr_large, "box": box, "seed": int(seed),
        "tests": list(tests), "mean_diameter": diameter,
        "threshold": threshold if sequential else None,
        "n_loads": n_loads if sequential else None,
        "max_steps": max_steps if sequential else None,
        "beta": beta if sequential else None,
        "contact_delta": contact_delta if sequential else None,
    }
    return JammingResult(
        params=params, network=net, local=bool(local_active.any()),
        local_rattler=~local_active, local_escape=escape,
        collective_test=collective, strict_test=strict, rattler=~backbone,
        forces=forces, statics=stat, volume=packing.volume, md_pressure=md_pressure,
        seconds=seconds,
    )
