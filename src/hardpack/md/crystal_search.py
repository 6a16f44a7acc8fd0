"""Search for dense crystal packings of spheroids with small-cell deforming-cell MD (Donev 2006,
ch. 8; Donev, Stillinger, Chaikin and Torquato, Phys. Rev. Lett. 92, 255506 (2004)).

Donev found the SM2 laminate (phi = 0.770732 at aspect ratio sqrt(3), 14 contacts per particle)
by compressing a few particles (4 to 16) per periodic cell from random starts with the
deforming-cell MD (Donev 2006, sec. 3.2.4.2), whose cell takes the shape of the densest
structure the particles find. One run here (:func:`search_run`):

1. A random start: ``n`` spheroids with random orientations in a cube at volume fraction
   ``phi_start`` (:func:`hardpack.initial.random_ellipsoid_packing`).
2. Isobaric MD without growth at the applied pressure p* = P v / kT (v the particle volume)
   for ``equilibration`` collisions per particle (:func:`hardpack.md.deforming.compress_deforming`
   with ``applied_pressure`` P = p* / v): the cell relaxes its volume and shape, and a small
   system at a solid-phase pressure orders in a few hundred collisions per particle.
3. Lubachevsky-Stillinger growth at ``growth_rate`` in the shape-only mode (the cell keeps its
   volume and relaxes its shape) to the reduced pressure ``max_pressure``, where the packing is
   jammed to phi_J - phi ~ d phi / Z.
4. ``cycles`` > 1 repeats steps 2 and 3 from the jammed packing (the isobaric stage melts or
   expands it back to the density of p*, new velocities) and keeps the densest jammed packing:
   LS growth can jam the cell in a lattice that a slower deformation would leave (one spheroid
   per cell at Gamma = 1e-3 ended at pi / sqrt(18) in 3 of 4 prolate and 1 of 4 oblate seeds,
   the others at phi = 0.680 to 0.740 with 6 to 10 contacts; at Gamma = 1e-2 none did; at
   Gamma = 1e-4 all of 6 oblate seeds and none of 6 prolate ones, which stopped at phi =
   0.737-0.739 with only 2-4 contacts within the contact tolerance, not a jammed lattice: the
   spheroid touches its own image at its equator, the shortest lattice vector perpendicular to
   its long axis to 1e-6, so the contact normal lies on the centre line, no spin can open the
   gap, the impulses grow as 1 / |r x n|^2 and the reduced pressure, whose kinetic part is the
   translational energy that a lone particle never exchanges, passes ``max_pressure`` before
   the cell has relaxed). Which seeds end where depends on the last bits of the arithmetic (the numba
   and numpy versions), so claims about the search are fractions over seeds.
5. With ``polish`` (the default), the densest jammed packing is polished by the SLP size ascent
   in the deforming cell (:func:`hardpack.jamming.ascent.ascend` with ``deform=True``, up to
   POLISH_ROUNDS rounds from the trust radius POLISH_RADIUS) to the local maximum of the density
   it lies near. An LS packing in a small deforming cell is jammed in its fixed cell at best, not
   strictly jammed: the cell mobility lags the growth (Donev 2006, Sec. 8.2.1: the densest outputs
   "are not truly strictly jammed"). Measured at n = 4: at alpha = sqrt(3) the LS runs that end
   0.770704 and 0.770731 polish to 0.7707316, the laminate to 7 digits, with 14 contacts; at
   alpha = 1.25 two runs at 0.74310-0.74330 polish to the laminate's 0.7433193 and two at 0.7341-0.7350
   climb to the affine FCC lattice, pi / sqrt(18). At alpha = 1 / sqrt(3) (n = 2, 4, seeds 0-19)
   2 of 40 runs polish to the laminate's 0.7707316 with 14 contacts, after 87 and 93 rounds (a cap
   of 50 left them at 0.7683 and 0.7688); the others end at pi / sqrt(18), 2-49 rounds.

Small cells need the collisions of a particle with its own periodic images, which the ellipsoid
kernel has (:mod:`hardpack.md._ellipsoid_deforming_kernel`): with ``n`` = 1 the run ends at
(or, when the growth jams the cell first, step 4, below) the densest lattice packing of the
shape, the affine image of FCC, phi = pi / sqrt(18) for every aspect ratio. The result is
compared with the densest known crystal of the same aspect ratio, the laminate
(:func:`hardpack.geometry.ellipsoid_crystals.laminate`), beyond sqrt(3) the laminate of sqrt(3)
stretched (:func:`hardpack.geometry.ellipsoid_crystals.stretched_laminate`, phi = 0.770732;
Donev 2006, Sec. 8.2, Fig. 8.2; phi(alpha) = phi(1 / alpha) for both): contacts are
pairs within a Perram-Wertheim gap mu - 1 < ``contact_tol``
(:func:`hardpack.geometry.ellipsoid_stats.ellipsoid_contacts`, own images counted twice).
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.md.compress import StopCriteria

#: default protocol (module docstring): start density, isobaric pressure p* = P v / kT, its
#: collisions per particle, the LS growth rate and the final reduced pressure
PHI_START, PRESSURE, EQUILIBRATION, GROWTH_RATE, MAX_PRESSURE = 0.3, 30.0, 2000, 1e-3, 1e9
#: contact tolerance on the Perram-Wertheim gap mu - 1, and the tolerance on phi of a match with
#: the laminate
CONTACT_TOL, MATCH_TOL = 1e-4, 1e-4
#: the polish (step 5): first trust radius and rounds at most of the size ascent
POLISH_RADIUS, POLISH_ROUNDS = 1e-2, 200
#: the numbers of a run that the polish gives
POLISH_KEYS = ("phi_polished", "contacts_polished", "min_contacts_polished", "max_contacts_polished",
               "polish_rounds", "polish_repairs")

log = logging.getLogger("hardpack.md")


def spheroid_semiaxes(alpha: float) -> np.ndarray:
    """Semiaxes (alpha, 1, 1) of a spheroid with aspect ratio alpha (prolate above 1, oblate below).

    Parameters
    ----------
    alpha : float
        Aspect ratio, positive and finite.

    Returns
    -------
    numpy.ndarray, shape (3,)
        The semiaxes.

    Raises
    ------
    InvalidInputError
        If alpha is not a positive finite number.
    """
    if isinstance(alpha, bool) or not isinstance(alpha, (int, float, np.floating)) or not (
            math.isfinite(alpha) and alpha > 0):
        raise InvalidInputError(f"the aspect ratio alpha must be a positive finite number, got {alpha!r}")
    return np.array([float(alpha), 1.0, 1.0])


def laminate_reference(alpha: float) -> tuple[float, float]:
    """phi and the mean contacts per particle of the densest known crystal of spheroids with
    aspect ratio alpha: the laminate, and beyond sqrt(3) (below 1 / sqrt(3)) the laminate of
    sqrt(3) stretched to alpha (Donev 2006, sec. 8.2, Eq. 8.3 and Fig. 8.2; phi(alpha) =
    phi(1 / alpha)).

    Parameters
    ----------
    alpha : float
        Aspect ratio.

    Returns
    -------
    phi : float
        Its density (0.770732 for every alpha >= sqrt(3)).
    contacts : float
        Its contacts per particle (14 from sqrt(3) on).
    """
    from hardpack.geometry.ellipsoid_crystals import DENSEST_ALPHA, laminate, stretch_for, stretched_laminate
    from hardpack.geometry.ellipsoid_stats import ellipsoid_contacts

    spheroid_semiaxes(alpha)
    prolate = float(max(alpha, 1.0 / alpha))
    crystal = laminate(prolate) if prolate <= DENSEST_ALPHA else stretched_laminate(stretch_for(prolate))
    contacts = ellipsoid_contacts(crystal, tol=CONTACT_TOL, min_contacts=1)
    return float(crystal.phi), float(contacts.degree.mean())


def search_run(n: int, alpha: float, seed: int, *, phi_start: float = PHI_START, pressure: float = PRESSURE,
               equilibration: int = EQUILIBRATION, growth_rate: float = GROWTH_RATE,
               max_pressure: float = MAX_PRESSURE, contact_tol: float = CONTACT_TOL, cycles: int = 1,
               polish: bool = True) -> dict:
    """One random-start crystal search run (module docstring).

    Parameters
    ----------
    n : int
        Spheroids per cell, >= 1.
    alpha : float
        Aspect ratio (semiaxes alpha, 1, 1).
    seed : int
        Seed of the start and of the velocities.
    phi_start : float
        Volume fraction of the random start.
    pressure : float
        Isobaric pressure p* = P v / kT of step 2 (> 0).
    equilibration : int
        Collisions per particle of step 2 (>= 0; 0 skips it).
    growth_rate : float
        LS growth rate of step 3 (> 0).
    max_pressure : float
        Reduced pressure at which step 3 stops.
    contact_tol : float
        Contact tolerance on mu - 1.
    cycles : int
        Isobaric-then-LS cycles (step 4), >= 1.
    polish : bool
        Polish the densest jammed packing by the size ascent in the deforming cell (step 5).

    Returns
    -------
    dict
        ``packing`` (the final Packing), ``phi``, ``Z`` (reduced pressure), ``contacts`` (mean per
        particle), ``min_contacts``, ``max_contacts``, ``n_overlapping`` (Perram-Wertheim check of
        the final packing), ``phi_equilibrated`` (after the first step 2), ``cpu_time`` (s),
        ``collisions``, ``best_cycle`` (the cycle of the densest packing, from 0); with
        ``polish``, ``polished`` (the polished Packing, free of overlaps), ``phi_polished``,
        ``contacts_polished``, ``min_contacts_polished``, ``max_contacts_polished``,
        ``polish_rounds`` and ``polish_repairs`` (:class:`hardpack.jamming.ascent.Ascent`), else
        NaN in their place.

    Raises
    ------
    InvalidInputError
        For a bad n, alpha, pressure, equilibration or rate.
    """
    from hardpack.geometry.ellipsoid_stats import ellipsoid_contacts
    from hardpack.initial import random_ellipsoid_packing
    from hardpack.jamming.ascent import ascend
    from hardpack.md.deforming import compress_deforming

    semiaxes = spheroid_semiaxes(alpha)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InvalidInputError(f"n (spheroids per cell) must be an integer >= 1, got {n!r}")
    if not (math.isfinite(pressure) and pressure > 0):
        raise InvalidInputError(f"the isobaric pressure p* must be a positive finite number, got {pressure!r}")
    if isinstance(equilibration, bool) or not isinstance(equilibration, (int, np.integer)) or equilibration < 0:
        raise InvalidInputError(f"equilibration (collisions per particle) must be an integer >= 0, "
                                f"got {equilibration!r}")
    if not (math.isfinite(growth_rate) and growth_rate > 0):
        raise InvalidInputError(f"the growth rate must be a positive finite number, got {growth_rate!r}")
    if isinstance(cycles, bool) or not isinstance(cycles, (int, np.integer)) or cycles < 1:
        raise InvalidInputError(f"cycles must be an integer >= 1, got {cycles!r}")
    started = time.process_time()
    packing = random_ellipsoid_packing(int(n), semiaxes, phi_start, seed=seed)
    volume = 4.0 / 3.0 * math.pi * float(np.prod(semiaxes))
    collisions = 0
    best, best_cycle, phi_equilibrated = None, 0, float("nan")
    for cycle in range(int(cycles)):
        if equilibration > 0:
            res = compress_deforming(packing, 0.0, seed + 2 * cycle,
                                     StopCriteria(max_pressure=None, max_collisions=int(equilibration) * int(n)),
                                     applied_pressure=pressure / volume)
            packing = res.packing
            collisions += res.stats["collisions"]
        if cycle == 0:
            phi_equilibrated = float(packing.phi)
        res = compress_deforming(packing, growth_rate, seed + 2 * cycle + 1, StopCriteria(max_pressure=max_pressure))
        collisions += int(res.stats["collisions"])
        packing = res.packing
        if best is None or packing.phi > best.packing.phi:
            best, best_cycle = res, cycle
    res = best
    final = res.packing
    contacts = ellipsoid_contacts(final, tol=contact_tol, min_contacts=1)
    polished = {"polished": None, **{k: float("nan") for k in POLISH_KEYS}}
    if polish:
        climbed = ascend(final, deform=True, radius=POLISH_RADIUS, rounds=POLISH_ROUNDS)
        touching = ellipsoid_contacts(climbed.packing, tol=contact_tol, min_contacts=1)
        polished = {"polished": climbed.packing, "phi_polished": climbed.phi,
                    "contacts_polished": float(touching.degree.mean()),
                    "min_contacts_polished": int(touching.degree.min()),
                    "max_contacts_polished": int(touching.degree.max()),
                    "polish_rounds": climbed.rounds, "polish_repairs": climbed.repairs}
    return {**polished,
        "packing": final, "phi": float(final.phi), "Z": float(res.stats["Z"]),
        "contacts": float(contacts.degree.mean()), "min_contacts": int(contacts.degree.min()),
        "max_contacts": int(contacts.degree.max()),
        "n_overlapping": int(final.overlap_report().n_overlapping), "phi_equilibrated": phi_equilibrated,
        "cpu_time": time.process_time() - started, "collisions": collisions, "best_cycle": best_cycle,
    }


def crystal_search(ns, alpha: float, seeds, **protocol) -> xr.Dataset:
    """Random-start crystal searches (:func:`search_run`) for every n per cell and seed, compared
    with the laminate.

    Parameters
    ----------
    ns : sequence of int
        Spheroids per cell.
    alpha : float
        Aspect ratio.
    seeds : sequence of int
        Seeds.
    **protocol
        Keyword arguments of :func:`search_run`.

    Returns
    -------
    xarray.Dataset
        On (n, seed): ``phi``, ``Z``, ``contacts``, ``min_contacts``, ``max_contacts``,
        ``n_overlapping``, ``phi_equilibrated``, ``cpu_time``, ``collisions``, the polish's
        POLISH_KEYS (NaN without it), ``laminate`` (phi within MATCH_TOL of the laminate's and
        every particle with its contact count) and ``laminate_polished`` (the same for the
        polished packing); attributes the laminate's ``phi_laminate`` and ``contacts_laminate``,
        the best phi as jammed (``phi_best``) and polished (``phi_best_polished``) and the
        protocol.
    """
    ns = [int(k) for k in ns]
    seeds = [int(s) for s in seeds]
    if not ns or not seeds:
        raise InvalidInputError("give at least one n per cell and one seed")
    phi_lam, z_lam = laminate_reference(alpha)
    keys = ("phi", "Z", "contacts", "min_contacts", "max_contacts", "n_overlapping", "phi_equilibrated",
            "cpu_time", "collisions", "best_cycle", *POLISH_KEYS)
    table = {k: np.full((len(ns), len(seeds)), np.nan) for k in keys}
    for a, n in enumerate(ns):
        for b, seed in enumerate(seeds):
            run = search_run(n, alpha, seed, **protocol)
            log.info("alpha %g, n = %d, seed %d: phi %.6f, contacts %d-%d, %.1f CPU-s (run %d of %d)", alpha, n,
                     seed, run["phi"], run["min_contacts"], run["max_contacts"], run["cpu_time"],
                     a * len(seeds) + b + 1, len(ns) * len(seeds))
            for k in keys:
                table[k][a, b] = run[k]
    def matches(suffix):
        return ((np.abs(table["phi" + suffix] - phi_lam) < MATCH_TOL) & (table["min_contacts" + suffix] == z_lam)
                & (table["max_contacts" + suffix] == z_lam))

    data = {k: (("n", "seed"), v) for k, v in table.items()}
    data["laminate"] = (("n", "seed"), matches(""))
    data["laminate_polished"] = (("n", "seed"), matches("_polished"))
    params = {"phi_start": PHI_START, "pressure": PRESSURE, "equilibration": EQUILIBRATION,
              "growth_rate": GROWTH_RATE, "max_pressure": MAX_PRESSURE, "contact_tol": CONTACT_TOL, "cycles": 1}
    params.update(protocol)
    return xr.Dataset(data, coords={"n": ns, "seed": seeds}, attrs={
        "hardpack_kind": "ellipsoid_crystal_search", "alpha": float(alpha), "phi_laminate": phi_lam,
        "contacts_laminate": z_lam, "match_tol": MATCH_TOL, "phi_best": float(np.nanmax(table["phi"])),
        "phi_best_polished": float(np.nanmax(table["phi_polished"])) if protocol.get("polish", True) else np.nan,
        **{k: float(v) for k, v in params.items()}})
