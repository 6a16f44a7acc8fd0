"""verify(packing): the full jamming verdict of a sphere packing (periodic, hard walls, container).

Steps (Donev 2006, dissertation ch. 4):
1. contact network within the relative gap ``delta`` (Eq. 4.5; sequential method:
   ``contact_delta``), all periodic images, and the contacts with hard walls or the container
   wall (sec. 4.4.3: a contact with a fixed point of the wall; :mod:`hardpack.jamming.contacts`);
2. local test and iterative rattler removal (LP 4.15, Alg. 13 step 4) -- always run, since
   the other tests need a rattler-free packing;
3. collective test (strain fixed) and strict test (strain with Tr eps <= 0), either with
   Algorithm 13 (``method="ideal"``: exact binary verdict for packings with tiny gaps) or
   Algorithm 14 (``method="sequential"``: random loading that moves the packing, for
   finite-rate packings with gaps; the verdict thresholds the mean displacement). The
   strict test starts from the collectively jammed backbone when there is one; with the ideal
   method, a packing without one is not strictly jammed either (strict implies collective,
   sec. 4.2.2) and no strict LP is solved. With hard walls the walls stay fixed: a closed
   container's strict test is its collective test, and one with periodic axes between walls is
   undetermined when collectively jammed (:func:`_fixed_walls_strict`), with either method (the
   sequential one moves the spheres against the fixed walls, sec. 4.4.3: a wall contact is a
   contact with a fixed point of the wall);
4. self-stress forces, contact number, isostaticity and pressure of the backbone
   (:mod:`hardpack.jamming.forces`); a backbone without a self-stress gets the forces of the
   nearest jamming point (near contacts within ``force_delta`` that close there carry force).

When every particle is a rattler there is no backbone and nothing can be jammed (Alg. 13 step
3): the collective and strict tests solve no LP and say "not jammed". The numerical fallbacks
of the LPs (:data:`hardpack.jamming.highs.FALLBACKS`) are counted in the result, and a test that
could not decide says "undetermined" with its reason.
"""

from __future__ import annotations

import logging
import time
from dataclasses import replace

import numpy as np

from hardpack.errors import InvalidInputError, check_seed
from hardpack.geometry.packing import Packing
from hardpack.io import checkpoint as ckpt
from hardpack.jamming.contacts import check_delta, contact_network, require_spheres
from hardpack.jamming.forces import jamming_point_forces, self_stress, statics
from hardpack.jamming.highs import FALLBACKS, recording_fallbacks
from hardpack.jamming.ideal import TestOutcome, ideal_test
from hardpack.jamming.near_sphere import ellipse_slope
from hardpack.jamming.rattlers import remove_rattlers
from hardpack.jamming.result import CATEGORIES, JammingResult
from hardpack.jamming.sequential import sequential_test

log = logging.getLogger(__name__)

METHODS = ("ideal", "sequential")
#: contact tolerance of the ideal test (LS packings at high pressure: contacts ~1e-12, the next
#: neighbours ~1e-6 and beyond) and of the contacts counted for Z, isostaticity and forces
DEFAULT_DELTA = 1e-6
#: neighbour-list tolerance of the sequential test: Donev's 0.1-1 D (Donev 2006, sec. 4.6.2.1), the first
#: coordination shell; each LP may then move a particle by up to delta D_min / 2 = 0.05 D
SEQUENTIAL_DELTA = 0.1


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


class _Saved:
    """The checkpoint of the sequential tests: one file with the state of each test after its
    last loading sequence, keys prefixed by the test's name. A finished test's state stays in it,
    so that a resumed verification takes that test's outcome and random generator from it."""

    def __init__(self, path, fingerprint: str):
        self.path, self.fingerprint = path, fingerprint
        self.state = {} if path is None else ckpt.load(path, fingerprint) or {}
        if self.state:
            log.info("resuming the sequential tests from %s", path)

    def hooks(self, test: str) -> dict:
        """``resume`` and ``save`` arguments of :func:`sequential_test` for ``test``."""
        if self.path is None:
            return {}
        prefix = f"{test}__"
        mine = {k.removeprefix(prefix): v for k, v in self.state.items() if k.startswith(prefix)}

        def save(state: dict) -> None:
            self.state = {k: v for k, v in self.state.items() if not k.startswith(prefix)}
            self.state.update({prefix + k: v for k, v in state.items()})
            ckpt.save(self.path, self.fingerprint, self.state)

        return {"resume": mine or None, "save": save}


def verify(
    packing: Packing,
    delta: float | None = None,
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
    force_delta: float | None = None,
    checkpoint=None,
    workers: int = 1,
) -> JammingResult:
    """Classify ``packing`` as locally / collectively / strictly jammed (see the module docstring).

    Parameters
    ----------
    packing : Packing
        A sphere packing without overlaps: periodic, between hard walls or in a spherical
        container (wall contacts are constraints and their forces the walls' reactions).
    delta : float, optional
        Relative gap tolerance for contacts, 0 < delta < 1; default DEFAULT_DELTA (1e-6)
        for the ideal method and SEQUENTIAL_DELTA (0.1) for the sequential one, whose
        neighbour list must reach the near contacts a loading sequence can close.
    tests : str or sequence of str, default ("local", "collective", "strict")
        Any of "local", "collective", "strict" (local always runs: the others need it).
    seed : int, default 0
        Non-negative seed of the random loads (results are reproducible for a given seed).
    method : {"ideal", "sequential"}, default "ideal"
        "ideal" (Algorithm 13) or "sequential" (Algorithm 14).
    dr_large : float, optional
        Displacement (absolute length) above which a particle counts as displaced in
        the ideal test and the local test; default delta (sequential: contact_delta) times the
        mean diameter (Alg. 13 step 2, "delta D ~ dr_large"). Must be below ``box``.
    box : float, optional
        Bound on each displacement component in the LPs; default the mean diameter.
    threshold, n_loads, max_steps, beta : float, int, int, float
        Sequential test only (mean displacement / D above which the packing is called
        unjammed, default 1e-3; loads, default 3; LPs per load direction, default 3; step
        size / D below which a loading sequence stops, default 0.01).
    md_pressure : float, optional
        Reduced pressure PV/(NkT) measured by the generator, compared with the
        free-volume pressure from the forces.
    contact_delta : float, optional
        Gap tolerance of the contacts that define the rattlers (the local test),
        Z, isostaticity and forces with ``method="sequential"``, whose ``delta`` (0.1-1, Donev
        2006, sec. 4.6.2.1) includes near neighbours on purpose; default min(delta, 1e-6). The ideal
        method uses ``delta``. Rattlers stay fixed obstacles in the sequential LPs.
    force_delta : float, optional
        When the backbone has no self-stress at the contact tolerance (a hypostatic
        finite-pressure packing), the forces are those of the nearest jamming point, found on
        the contacts within this tolerance (default SEQUENTIAL_DELTA, the first shell; see
        :func:`hardpack.jamming.forces.jamming_point_forces`). The result's network then also
        holds the near contacts that carry force; Z and the isostaticity counts leave them out.
    checkpoint : str or os.PathLike, optional
        Sequential method only: path of a checkpoint written after every loading
        sequence (:mod:`hardpack.io.checkpoint`); a killed verification started again with the
        same arguments resumes from it and gives the result of an uninterrupted one. It is
        removed when the verification ends.
    workers : int, default 1
        Sequential method only: loading sequences run at once, each in its own process
        (they are independent; the result does not depend on this number).

    Returns
    -------
    JammingResult
        The verdicts ``local``, ``collective``, ``strict`` (None: not run or undetermined, with
        the reason in ``undetermined``), the contact ``network``, the ``rattler`` mask, the
        backbone ``forces`` and ``statics``, the test outcomes, ``params``, ``seconds`` and the
        ``fallbacks`` counts; :meth:`JammingResult.to_dataset` stores it.

    Raises
    ------
    InvalidInputError
        If ``packing`` is not a sphere Packing or overlaps; ``method`` or a test name is
        unknown; ``delta``, ``contact_delta`` or ``force_delta`` is not in (0, 1); ``seed`` is not a non-negative
        integer; ``dr_large``, ``box``, ``threshold``, ``beta`` or
        ``md_pressure`` is not a positive finite number; ``n_loads``, ``max_steps`` or
        ``workers`` is not a positive integer; dr_large >= box; the sequential test could never
        reach ``threshold`` (max_steps * delta * r_min < threshold D); or ``checkpoint`` is
        given with the ideal method.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError(
            f"verify expects a hardpack Packing, got {type(packing).__name__}"
        )
    require_spheres(packing)
    if method not in METHODS:
        raise InvalidInputError(f"method must be one of {METHODS}, got {method!r}")
    delta = check_delta((SEQUENTIAL_DELTA if method == "sequential" else DEFAULT_DELTA) if delta is None else delta)
    tests = _check_tests(tests)
    check_seed(seed)
    diameter = 2.0 * float(packing.radii.mean())
    sequential = method == "sequential"
    if sequential:
        contact_delta = min(delta, DEFAULT_DELTA) if contact_delta is None else check_delta(contact_delta)
    else:
        contact_delta = delta
    dr_large = contact_delta * diameter if dr_large is None else _positive("dr_large", dr_large)
    box = diameter if box is None else _positive("box", box)
    threshold = _positive("threshold", threshold)
    beta = _positive("beta", beta)
    for name, value in (("n_loads", n_loads), ("max_steps", max_steps), ("workers", workers)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise InvalidInputError(f"{name} must be a positive integer, got {value!r}")
    if md_pressure is not None:
        md_pressure = _positive("md_pressure", md_pressure)
    reach = max_steps * delta * float(packing.radii.min()) / diameter
    if method == "sequential" and reach < threshold:
        raise InvalidInputError(
            f"the sequential test with delta = {delta:g} and max_steps = {max_steps} can move a "
            f"particle by at most max_steps * delta * r_min = {reach:.3g} D per loading sequence, "
            f"below the threshold {threshold:g} D: it could never report 'not jammed'. Use a "
            f"neighbour-list tolerance delta >= {threshold * diameter / (max_steps * packing.radii.min()):.3g} "
            f"(Donev: 0.1-1, the default is {SEQUENTIAL_DELTA:g})"
        )
    if checkpoint is not None and not sequential:
        raise InvalidInputError("a checkpoint is for the sequential method, whose loading sequences "
                                "it saves; the ideal method runs without one")
    if dr_large >= box:
        raise InvalidInputError(
            f"dr_large = {dr_large:g} must be smaller than the LP box {box:g}, otherwise no "
            "displacement can ever count as unjamming"
        )

    rng = np.random.default_rng(int(seed))
    with recording_fallbacks() as fallbacks:
        result = _verify(packing, tests, rng, method=method, delta=delta, contact_delta=contact_delta,
                         dr_large=dr_large, box=box, threshold=threshold, n_loads=n_loads,
                         max_steps=max_steps, beta=beta, workers=workers, checkpoint=checkpoint,
                         seed=int(seed), force_delta=force_delta, md_pressure=md_pressure)
    counted = []  # the sequential tests' own, from their sequences; once for a fixed-wall strict test,
    for test in (result.collective_test, result.strict_test):  # which is the collective one
        own = getattr(test, "fallbacks", None)
        if own is not None and not any(own is seen for seen in counted):
            fallbacks.update(own)
            counted.append(own)
    result.fallbacks = {name: int(fallbacks[name]) for name in FALLBACKS}
    return result


def _verify(packing: Packing, tests: tuple, rng: np.random.Generator, *, method: str, delta: float,
            contact_delta: float, dr_large: float, box: float, threshold: float, n_loads: int,
            max_steps: int, beta: float, workers: int, checkpoint, seed: int, force_delta,
            md_pressure) -> JammingResult:
    """The steps of the module docstring, with the arguments :func:`verify` checked."""
    diameter = 2.0 * float(packing.radii.mean())
    sequential = method == "sequential"
    seconds = {}
    t0 = time.perf_counter()
    net = contact_network(packing, contact_delta)
    seconds["contacts"] = time.perf_counter() - t0
    n = packing.n_particles

    t0 = time.perf_counter()
    local_active, escape = remove_rattlers(
        net, np.ones(n, dtype=bool), dr_large=dr_large, box=box, rng=rng
    )
    seconds["local"] = time.perf_counter() - t0
    log.info("%d contacts within %g; local test: %d of %d particles are rattlers (%.1f s)",
             net.n_contacts, contact_delta, int((~local_active).sum()), n, seconds["local"])

    collective = strict = None
    common = {"box": box, "rng": rng}
    if method == "ideal":
        if "collective" in tests:
            collective = ideal_test(net, local_active, strict=False, dr_large=dr_large, **common)
            seconds["collective"] = collective.seconds
        if "strict" in tests and not net.is_periodic:
            strict = _fixed_walls_strict(net, local_active, collective, dr_large=dr_large, **common)
            seconds["strict"] = strict.seconds
        elif "strict" in tests and collective is not None and not collective.jammed:
            # strict jamming implies collective jamming (Donev 2006, sec. 4.2.2): no LP needed
            strict = replace(collective, test="strict", method="implied by the collective test",
                             n_lp=0, seconds=0.0, loads=[])
            seconds["strict"] = 0.0
        elif "strict" in tests:
            start = collective.backbone if collective is not None and collective.jammed else local_active
            strict = ideal_test(net, start, strict=True, dr_large=dr_large, **common)
            seconds["strict"] = strict.seconds
        backbone = collective.backbone if collective is not None and collective.jammed else local_active
    else:
        kwargs = {"rattlers": ~local_active, "threshold": threshold, "beta": beta,
                  "n_loads": n_loads, "max_steps": max_steps, "workers": workers, **common}
        saved = _Saved(checkpoint, ckpt.fingerprint(
            packing, run="verify", delta=delta, seed=seed, tests=list(tests), dr_large=dr_large,
            box=box, threshold=threshold, n_loads=n_loads, max_steps=max_steps, beta=beta,
            contact_delta=contact_delta))
        walls = not net.is_periodic  # the walls stay fixed: the strict test needs the collective one
        if "collective" in tests or (walls and "strict" in tests):
            fixed = sequential_test(packing, delta, strict=False, **kwargs, **saved.hooks("collective"))
            if "collective" in tests:
                collective = fixed
                seconds["collective"] = collective.seconds
        if "strict" in tests and walls:
            strict = _fixed_walls_strict(net, local_active, fixed, dr_large=dr_large, **common)
            seconds["strict"] = strict.seconds
        elif "strict" in tests:
            strict = sequential_test(packing, delta, strict=True, **kwargs, **saved.hooks("strict"))
            seconds["strict"] = strict.seconds
        backbone = local_active

    log.info("contact forces of the %d-particle backbone", int(backbone.sum()))
    t0 = time.perf_counter()
    d, nb = packing.dim, int(backbone.sum())
    # hypostatic by count: straight to the nearest jamming point, whose LP also finds a
    # self-stress of the contacts themselves if there is one (their gaps cost least)
    hypostatic = int(net.among(backbone).sum()) < d * nb - net.n_trivial + 1
    forces = None if hypostatic else self_stress(net, backbone)
    counted, near = None, {}
    if (forces is None or not forces.exists) and backbone.any():  # the nearest jamming point
        force_delta = max(SEQUENTIAL_DELTA, contact_delta) if force_delta is None else check_delta(force_delta)
        found = jamming_point_forces(contact_network(packing, force_delta), backbone, contact_delta, box)
        if found is not None:
            net, forces = found
            counted = net.distance / net.contact_distance - 1.0 <= contact_delta
            near = {"force_delta": force_delta, "force_near_contacts": int((~counted).sum())}
    if forces is None:
        forces = self_stress(net, backbone)
    stat = statics(net, backbone, forces, packing.volume, counted)
    slope = None
    if d == 2 and forces.exists and net.is_periodic:
        slope = ellipse_slope(net.separation, net.i, net.j, forces.forces, packing.radii).slope
    seconds["forces"] = time.perf_counter() - t0

    if checkpoint is not None:
        ckpt.remove(checkpoint)
    params = {
        "boundary": str(packing.boundary),
        "method": method, "delta": delta, "dr_large": dr_large, "box": box, "seed": seed,
        "tests": list(tests), "mean_diameter": diameter,
        "threshold": threshold if sequential else None,
        "n_loads": n_loads if sequential else None,
        "max_steps": max_steps if sequential else None,
        "beta": beta if sequential else None,
        "contact_delta": contact_delta if sequential else None,
        **near,
    }
    return JammingResult(
        params=params, network=net, local=bool(local_active.any()),
        local_rattler=~local_active, local_escape=escape,
        collective_test=collective, strict_test=strict, rattler=~backbone,
        forces=forces, statics=stat, volume=packing.volume, md_pressure=md_pressure,
        ellipse_slope=slope, seconds=seconds,
    )


def _fixed_walls_strict(net, local_active, collective, *, dr_large, box, rng):
    """The strict test of a packing with hard walls or in a container. Strict jamming also allows
    volume-nonincreasing deformations of the boundary (Donev 2006, sec. 4.2.2); the text makes
    them concrete for the lattice of a periodic cell only (sec. 4.4.5) and treats hard walls as
    fixed (sec. 4.4.2). Here the walls stay fixed too, so a closed container (walls on every
    axis, or a spherical container) has no boundary deformation and its strict test is the
    collective test (run here if it was not). Walls on some axes with periodic others would need
    the strain of the periodic lattice vectors between fixed walls, which is not implemented:
    that strict test is undetermined, with the reason. ``collective`` is the collective test's
    outcome (ideal or sequential), or None to run the ideal one here."""
    if collective is None:
        collective = ideal_test(net, local_active, strict=False, dr_large=dr_large, box=box, rng=rng)
    if not net.periodic.any():
        return replace(collective, test="strict", method="walls fixed: the collective test")
    cleared = {"loads": []} if isinstance(collective, TestOutcome) else {}
    out = replace(collective, test="strict", method="not implemented", n_lp=0, seconds=0.0, **cleared)
    if out.jammed:
        out.undetermined = ("strict jamming between hard walls with periodic axes (a periodic cell "
                            "deforming between fixed walls) is not implemented")
    return out
