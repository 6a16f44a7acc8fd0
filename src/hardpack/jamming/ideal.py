"""Algorithm 13 (randomised LP test for ideal packings): collective or strict jamming.

Donev 2006, dissertation sec. 4.6.1 (Algorithm 13):

1. collective: strain fixed at 0; strict: strain variables and Tr eps <= 0 (LP 4.10 + 4.17);
3. no particles left -> not jammed;
   (each LP is solved exactly through one sparse LU and a K-variable LP when the particles form
   a rigid backbone with K <= 12 self-stresses, one of them positive,
   :mod:`hardpack.jamming.isostatic`; by HiGHS otherwise)
4. remove rattlers iteratively (:mod:`hardpack.jamming.rattlers`);
5-7. random load B, solve the LP, remove every particle displaced by >= dr_large;
8. repeat 3-4, then the same with -B;
9. neither load displaced anything -> the remaining (sub)packing is jammed; else back to 3.

Displacements are measured *relative to the bulk*: the LP pins the mean displacement, and the
componentwise median over the tested particles is then subtracted (translations are trivial
motions, sec. 4.3.2); with hard walls only along the periodic axes, and in a spherical container
the least-squares rotation about its centre is subtracted instead (its rotations are the
trivial motions). The median is used instead of the mean so that a large rattling cluster
does not make the whole backbone look displaced. In the strict test the measured displacement
is the non-affine part dr_i - eps x_i (gauge independent: a different choice of the periodic
image of particle i shifts both terms by eps Lambda m). A strain with
``|eps|_2 * cell_length >= dr_large`` is an unjamming motion of the cell; since removing
particles only relaxes constraints, no subpacking can then be strictly jammed, and the test
stops with "not strictly jammed".
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from hardpack.jamming.contacts import ContactNetwork
from hardpack.jamming.isostatic import RigidBackbone
from hardpack.jamming.lp import VolumeIncrease, random_strain_load, solve_motion
from hardpack.jamming.rattlers import neighbours_of, remove_rattlers
from hardpack.jamming.rigidity import rotation_velocities

log = logging.getLogger(__name__)


@dataclass
class TestOutcome:
    """Result of one jamming test (collective or strict). ``jammed`` is False also when
    ``undetermined`` holds a reason (an LP whose strain violates the volume constraint beyond
    the LP's accuracy, :class:`hardpack.jamming.lp.VolumeIncrease`: neither a motion nor a proof).

    Attributes
    ----------
    test : str
        "collective" or "strict".
    jammed : bool
        The verdict.
    backbone : numpy.ndarray of bool, shape (N,)
        Particles of the jammed subpacking (all False if not jammed).
    displacement : numpy.ndarray of float, shape (N,)
        Largest relative |dr_i| seen over all loads (NaN: untested).
    motion : numpy.ndarray of float, shape (N, d)
        First unjamming motion found (zeros if none).
    strain : numpy.ndarray of float, shape (d, d), or None
        Strain of that motion (strict test).
    n_lp : int
        Number of LPs solved.
    seconds : float
        Wall time.
    method : str
        The test's algorithm.
    loads : list of dict
        Per LP: max, mean, removed, strain.
    undetermined : str
        Why the test could not decide ("" when it did).
    """

    test: str
    jammed: bool
    backbone: np.ndarray  # (N,) particles of the jammed subpacking (all False if not jammed)
    displacement: np.ndarray  # (N,) largest relative |dr_i| seen over all loads (NaN: untested)
    motion: np.ndarray  # (N, d) first unjamming motion found (zeros if none)
    strain: np.ndarray | None  # (d, d) strain of that motion (strict test)
    n_lp: int = 0
    seconds: float = 0.0
    method: str = "ideal"
    loads: list = field(default_factory=list)  # per LP: dict(max, mean, removed, strain)
    undetermined: str = ""  # why the test could not decide ("" when it did)

    @property
    def max_displacement(self) -> float:
        """Largest displacement of the unjamming motion found (0 if none)."""
        return float(np.linalg.norm(self.motion, axis=1).max(initial=0.0))

    @property
    def strain_norm(self) -> float:
        return 0.0 if self.strain is None else float(np.linalg.norm(self.strain, 2))


def cell_length(lattice: np.ndarray) -> float:
    """Length of the longest lattice vector (scale of the boundary displacement eps * L).

    Parameters
    ----------
    lattice : numpy.ndarray of float, shape (d, d)
        Cell, lattice vectors as columns.

    Returns
    -------
    float
        max_k |lattice[:, k]|.
    """
    return float(np.linalg.norm(lattice, axis=0).max())


def relative_displacement(net: ContactNetwork, moving: np.ndarray, disp: np.ndarray,
                          eps: np.ndarray | None) -> np.ndarray:
    """Non-affine displacement dr_i - eps x_i less its trivial part over ``moving``: the
    componentwise median along the periodic axes (translations), or in a spherical container
    the least-squares rotation about its centre.

    Parameters
    ----------
    net : ContactNetwork
        The contact network (positions, boundary).
    moving : numpy.ndarray of bool, shape (N,)
        Particles with displacement variables.
    disp : numpy.ndarray of float, shape (N, d)
        Displacements dr.
    eps : numpy.ndarray of float, shape (d, d), or None
        Strain of the cell (None: fixed cell).

    Returns
    -------
    numpy.ndarray of float, shape (N, d)
        The relative displacements (0 for particles not moving).
    """
    rel = disp - (net.positions @ eps.T if eps is not None else 0.0)
    rel = np.where(moving[:, None], rel, 0.0)
    if not moving.any():
        return rel
    if net.centre is not None:
        gens = rotation_velocities(net.positions[moving] - net.centre)
        if gens.size:
            omega = np.linalg.lstsq(gens.T, rel[moving].ravel(), rcond=None)[0]
            rel[moving] -= (omega @ gens).reshape(-1, net.dim)
    elif net.is_periodic:
        rel[moving] -= np.median(rel[moving], axis=0)
    else:
        axes = np.flatnonzero(net.periodic)
        rel[np.ix_(moving, axes)] -= np.median(rel[np.ix_(moving, axes)], axis=0)
    return rel


def ideal_test(
    net: ContactNetwork,
    start: np.ndarray,
    *,
    strict: bool,
    dr_large: float,
    box: float,
    rng: np.random.Generator,
    max_rounds: int = 100,
) -> TestOutcome:
    """Algorithm 13 on the particles ``start`` (already free of rattlers, or not).

    Donev 2006, sec. 4.6.1; the steps and the measure of displacement are in the module
    docstring.

    Parameters
    ----------
    net : ContactNetwork
        The contacts of the packing (:func:`hardpack.jamming.contacts.contact_network`).
    start : numpy.ndarray of bool, shape (N,)
        The particles to test; rattlers among them are removed first (not modified in place).
    strict : bool
        False: collective test (fixed cell); True: strict test (strain variables with
        Tr eps <= 0, LP 4.10 + 4.17).
    dr_large : float
        Displacement (absolute length) from which a particle counts as displaced (step 7), and
        from which a strain with |eps|_2 times the longest lattice vector unjams the cell.
    box : float
        Bound on each displacement component in the LPs (absolute length).
    rng : numpy.random.Generator
        Source of the random loads.
    max_rounds : int, default 100
        Most rounds of loads B, -B (steps 3-9) before giving up with "not jammed".

    Returns
    -------
    TestOutcome
        ``jammed`` and the jammed subpacking ``backbone`` (N,), the largest relative
        displacement of each particle over all loads ``displacement`` (N,; NaN untested), the
        first unjamming ``motion`` (N, d) and its ``strain`` (strict test), per-LP ``loads``,
        ``n_lp``, ``seconds``, and ``undetermined`` with the reason when an LP's strain violates
        the volume constraint beyond its accuracy (then ``jammed`` is False).
    """
    t0 = time.perf_counter()
    n, d = net.n_particles, net.dim
    length = cell_length(net.lattice)
    active, _ = remove_rattlers(net, start, dr_large=dr_large, box=box, rng=rng)
    out = TestOutcome(
        test="strict" if strict else "collective", jammed=False,
        backbone=np.zeros(n, dtype=bool), displacement=np.full(n, np.nan),
        motion=np.zeros((n, d)), strain=None,
    )
    cache = {}
    for _ in range(max_rounds):
        if not active.any():
            break
        base = rng.standard_normal((n, d))
        base_eps = random_strain_load(rng, d, length) if strict else None
        displaced = False
        for sign in (1.0, -1.0):
            if not active.any():
                break
            load = sign * _centred(base, active)
            strain_load = None if base_eps is None else sign * base_eps
            try:
                disp, eps = _solve(net, active, load, strain_load, box, length, cache)
            except VolumeIncrease as exc:
                out.undetermined = f"LP {out.n_lp + 1}: {exc}"
                log.warning("%s test undetermined: %s", out.test, out.undetermined)
                out.seconds = time.perf_counter() - t0
                return out
            out.n_lp += 1
            rel = relative_displacement(net, active, disp, eps)
            size = np.linalg.norm(rel, axis=1)
            out.displacement[active] = np.fmax(out.displacement[active], size[active])
            strain_size = 0.0 if eps is None else np.linalg.norm(eps, 2) * length
            moved = active & (size >= dr_large)
            out.loads.append({
                "max": float(size[active].max()), "mean": float(size[active].mean()),
                "removed": int(moved.sum()), "strain": float(strain_size),
            })
            log.info("%s test, LP %d: %d particles, max displacement %.3g, %d displaced by >= %.3g",
                     out.test, out.n_lp, int(active.sum()), out.loads[-1]["max"], int(moved.sum()), dr_large)
            if (moved.any() or strain_size >= dr_large) and not out.motion.any():
                out.motion, out.strain = rel, eps
            if strain_size >= dr_large:  # the cell itself deforms: no strictly jammed subpacking
                active[:] = False
                break
            if moved.any():
                displaced = True
                active &= ~moved
                active, _ = remove_rattlers(
                    net, active, dr_large=dr_large, box=box, rng=rng,
                    recheck=neighbours_of(net, moved, active),
                )
        if not displaced and active.any():
            out.jammed = True
            out.backbone = active
            break
    out.seconds = time.perf_counter() - t0
    return out


def _solve(net, active, load, strain_load, box, length, cache):
    """LP (4.10) for the particles ``active``: solved through the self-stress space when they
    form a rigid backbone with few self-stresses and a positive one
    (:mod:`hardpack.jamming.isostatic`), by HiGHS otherwise. Returns (displacement, strain)."""
    key = active.tobytes()
    if key not in cache:
        cache.clear()
        cache[key] = RigidBackbone.build(net, active)
    iso = cache[key]
    if iso is not None:
        if strain_load is not None:
            mode = iso.strain_mode(net, strain_load, box, length)
            if mode is not None:
                return mode
        else:
            vertex = iso.optimum(load, net.dim, box)
            if vertex is not None:
                return vertex[0], None
    mot = solve_motion(net, active, load, box=box, cell_length=length, strain_load=strain_load)
    return mot.displacement, mot.strain


def _centred(load: np.ndarray, mask: np.ndarray) -> np.ndarray:
    out = np.where(mask[:, None], load, 0.0)
    if mask.any():
        out[mask] -= out[mask].mean(axis=0)
    return out
