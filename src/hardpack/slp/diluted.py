"""Low-density jammed packings by diluting SLP MRJ packings (Torquato & Jiao 2010, Sec. VI).

The protocol of the paper's Sec. VI (red squares of its Fig. 6): remove a small fraction
f_s = 0.1 %-2.5 % of the spheres of an SLP MRJ packing, which leaves an unjammed packing, and
jam the rest again with SLP; repeat n_r = 5-10 times, until the density stops falling. The paper
reports jammed packings with phi in [0.6, 0.64] (phi ~ 0.595 without the rattlers), strictly
jammed (abstract), with Z ~ 6.3 at phi ~ 0.6.

Our reading of the text, where it leaves a choice:

- every round removes the same number of spheres, ``round(f_s N_0)`` with N_0 the sphere count of
  the MRJ packing ("a small fraction of particles are removed from MRJ packings"), chosen
  uniformly among all spheres present (rattlers included: the text names no other rule);
- the re-jamming uses the SLP settings of the MRJ packing (the text says only "compressed to a
  jammed state using the SLP algorithm");
- the number of rounds is fixed in advance (the text stops at "a lower limit" of phi, which it
  reached in 5-10 rounds); the density of every round is recorded, so a plateau is visible.

Whether a round's packing is jammed is not decided here: every packing goes to
:func:`hardpack.jamming.verify` (``hardpack verify``) like the other SLP packings.

Random choice: round r draws from ``numpy.random.default_rng((seed, r))``, so the spheres removed
depend only on the seed, the round and the packing, and a resumed run removes the same ones.
Checkpoints: with ``checkpoint``, the packings of the finished rounds are written atomically
after every round (:mod:`hardpack.io.checkpoint`), and the re-jamming of the running round keeps
its own SLP checkpoint beside it (``<checkpoint>.slp``, :func:`hardpack.slp.driver.run_slp`). A
killed run started again with the same arguments continues with the first unfinished round and
ends with the packings of the uninterrupted run (every step is deterministic). Both files are
removed at the end.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError, check_seed
from hardpack.geometry import ball_volume
from hardpack.geometry.packing import Packing
from hardpack.io import checkpoint as ckpt
from hardpack.io import load_judged_packings, packing_to_dataset
from hardpack.slp.driver import run_slp
from hardpack.slp.lp import Bounds

log = logging.getLogger(__name__)

#: numbers recorded per round (besides the packing), in checkpoint order
ROUND_FIELDS = ("n_removed", "phi_diluted", "converged", "n_steps", "n_rejected", "wall_seconds", "cpu_seconds")


@dataclass(frozen=True)
class DilutedRound:
    """One round of the protocol: the re-jammed packing and how it was made.

    ``start_index``: index of each sphere in the MRJ start packing; ``n_removed``: spheres removed
    in this round; ``phi_diluted``: density right after the removal (before re-jamming);
    ``converged``, ``n_steps``, ``n_rejected``, ``wall_seconds``, ``cpu_seconds``: the SLP run's
    (:class:`hardpack.slp.driver.SLPResult`).

    Attributes
    ----------
    packing : Packing
        The re-jammed packing of this round.
    start_index : numpy.ndarray of int, shape (N,)
        Index of each sphere in the MRJ start packing.
    n_removed : int
        Spheres removed in this round.
    phi_diluted : float
        Density right after the removal (before re-jamming).
    converged, n_steps, n_rejected, wall_seconds, cpu_seconds
        The SLP run's (:class:`hardpack.slp.driver.SLPResult`).
    """

    packing: Packing
    start_index: np.ndarray
    n_removed: int
    phi_diluted: float
    converged: bool
    n_steps: int
    n_rejected: int
    wall_seconds: float
    cpu_seconds: float

    def to_dataset(self, **attrs) -> xr.Dataset:
        """The re-jammed packing as a Dataset with the round's outcome as attributes.

        Parameters
        ----------
        **attrs
            Further attributes (e.g. the protocol parameters, the start file, the round number).

        Returns
        -------
        xarray.Dataset
            The packing layout of :func:`hardpack.io.packing_to_dataset` with the data variable
            ``start_index`` and the attributes ``n_removed``, ``phi_diluted``, ``converged``,
            ``n_steps``, ``n_rejected``, ``wall_seconds``, ``cpu_seconds`` and ``attrs``.
        """
        outcome = dict(n_removed=self.n_removed, phi_diluted=self.phi_diluted, converged=self.converged,
                       n_steps=self.n_steps, n_rejected=self.n_rejected, wall_seconds=self.wall_seconds,
                       cpu_seconds=self.cpu_seconds)
        extra = {"start_index": (("particle",), np.asarray(self.start_index))}
        return packing_to_dataset(self.packing, {**attrs, **outcome}, extra)


def removal_count(n_start: int, fraction: float, rounds: int) -> int:
    """Spheres removed per round, ``round(fraction * n_start)``; refuses settings that remove
    none or leave fewer than two spheres after ``rounds`` rounds.

    Parameters
    ----------
    n_start : int
        Spheres in the start packing.
    fraction : float
        Fraction removed per round, in (0, 1).
    rounds : int
        Number of rounds, >= 1.

    Returns
    -------
    int
        Spheres removed per round.

    Raises
    ------
    InvalidInputError
        For settings that remove none or too many.
    """
    if not (0 < fraction < 1):
        raise InvalidInputError(f"fraction must be in (0, 1), got {fraction}")
    if int(rounds) != rounds or rounds < 1:
        raise InvalidInputError(f"rounds must be a positive integer, got {rounds}")
    n_remove = int(round(fraction * n_start))
    if n_remove < 1:
        raise InvalidInputError(
            f"fraction {fraction:g} of {n_start} spheres removes none per round; "
            f"use a fraction of at least {0.5 / n_start:.3g} or a larger packing")
    if n_start - rounds * n_remove < 2:
        raise InvalidInputError(
            f"{rounds} rounds of {n_remove} removals leave {n_start - rounds * n_remove} of "
            f"{n_start} spheres; lower the fraction or the number of rounds")
    return n_remove


def remove_random(packing: Packing, n_remove: int, rng: np.random.Generator) -> tuple[Packing, np.ndarray]:
    """``packing`` without ``n_remove`` spheres chosen uniformly at random, and the kept indices.

    Parameters
    ----------
    packing : Packing
        The packing.
    n_remove : int
        Spheres removed, in [1, N - 1].
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    packing : Packing
        The thinned packing.
    keep : numpy.ndarray of int, shape (N - n_remove,)
        Indices of the kept spheres, ascending.
    """
    if int(n_remove) != n_remove or not 0 < n_remove < packing.n_particles:
        raise InvalidInputError(
            f"cannot remove {n_remove} of {packing.n_particles} spheres; remove between 1 and N - 1")
    removed = rng.choice(packing.n_particles, size=int(n_remove), replace=False)
    keep = np.setdiff1d(np.arange(packing.n_particles), removed)
    species = None if packing.species is None else packing.species[keep]
    return Packing(packing.positions[keep], packing.radii[keep], packing.lattice, species=species), keep


def run_diluted(packing: Packing, fraction: float, rounds: int, seed: int, alpha: float, bounds: Bounds,
                deforming: bool = True, tol: float = 1e-10, max_steps: int = 2000, method: str = "highs-ipm",
                checkpoint=None, checkpoint_interval: float = 300.0,
                keep_checkpoint: bool = False) -> list[DilutedRound]:
    """The diluted-MRJ protocol (module docstring) from the jammed SLP packing ``packing``.

    Parameters
    ----------
    packing : Packing
        The start, an SLP MRJ packing (round 0).
    fraction : float
        f_s, the fraction of the start's spheres removed in every round (the paper: 0.001-0.025).
    rounds : int
        n_r, the number of removal and re-jamming rounds (the paper: 5-10).
    seed : int
        Seed of the random removals (round r uses ``default_rng((seed, r))``).
    alpha, bounds, deforming, tol, max_steps, method
        The SLP settings of every re-jamming (:func:`hardpack.slp.driver.run_slp`).
    checkpoint : path, optional
        Resumable checkpoint (module docstring), removed when the run ends unless
        ``keep_checkpoint`` (the caller removes it once the rounds are written).
    checkpoint_interval : float
        Seconds between the SLP checkpoints within a round.
    keep_checkpoint : bool, default False
        Leave the checkpoint for the caller to remove.

    Returns
    -------
    list of DilutedRound
        Rounds 1..``rounds`` in order.

    Raises
    ------
    InvalidInputError
        If ``packing`` is not a periodic sphere packing, ``seed`` is not a non-negative
        integer, ``fraction`` is not in (0, 1), ``rounds`` is not a positive integer, the
        fraction removes no sphere per round or the rounds leave fewer than two, or an SLP
        re-jamming refuses its settings (:func:`hardpack.slp.driver.run_slp`).
    hardpack.io.interrupt.Interrupted
        On SIGINT or SIGTERM, after the checkpoint is written.
    """
    packing.require_periodic_spheres("the diluted-MRJ protocol")
    check_seed(seed)
    n_remove = removal_count(packing.n_particles, fraction, rounds)
    fp = ckpt.fingerprint(packing, run="slp_diluted", fraction=float(fraction), seed=int(seed),
                          alpha=float(alpha), bounds=[bounds.strain, bounds.shear, bounds.displacement],
                          deforming=bool(deforming), tol=float(tol), max_steps=int(max_steps), method=method)
    done = [] if checkpoint is None else _load(checkpoint, fp)
    if done:
        log.info("resumed from %s after round %d (phi = %.8f)", checkpoint, len(done), done[-1].packing.phi)
    slp_checkpoint = None if checkpoint is None else Path(f"{checkpoint}.slp")
    current, index = (done[-1].packing, done[-1].start_index) if done else (packing, np.arange(packing.n_particles))
    for r in range(len(done) + 1, int(rounds) + 1):
        diluted, keep = remove_random(current, n_remove, np.random.default_rng((int(seed), r)))
        result = run_slp(diluted, alpha, bounds, deforming=deforming, tol=tol, max_steps=max_steps,
                         method=method, checkpoint=slp_checkpoint, checkpoint_interval=checkpoint_interval)
        current, index = result.packing, index[keep]
        done.append(DilutedRound(current, index, n_remove, diluted.phi, result.converged, result.n_steps,
                                 result.n_rejected, result.wall_seconds, result.cpu_seconds))
        log.info("diluted round %d: %d spheres removed, phi %.6f -> %.8f after %d LPs (converged=%s)",
                 r, n_remove, diluted.phi, current.phi, result.n_steps, result.converged)
        if checkpoint is not None and r < rounds:
            _save(checkpoint, fp, done)
    if checkpoint is not None and not keep_checkpoint:
        ckpt.remove(checkpoint)
    return done[: int(rounds)]


def _save(path, fp: str, done: list[DilutedRound]) -> None:
    state = {"numbers": np.array([[float(getattr(r, name)) for name in ROUND_FIELDS] for r in done])}
    for k, r in enumerate(done):
        state[f"positions_{k}"], state[f"radii_{k}"] = r.packing.positions, r.packing.radii
        state[f"lattice_{k}"], state[f"start_index_{k}"] = r.packing.lattice, r.start_index
        if r.packing.species is not None:
            state[f"species_{k}"] = r.packing.species
    ckpt.save(path, fp, state)


def _load(path, fp: str) -> list[DilutedRound]:
    state = ckpt.load(path, fp)
    if state is None:
        return []
    numbers = np.atleast_2d(state["numbers"])
    done = []
    for k, row in enumerate(numbers):
        values = dict(zip(ROUND_FIELDS, row.tolist()))
        packing = Packing(state[f"positions_{k}"], state[f"radii_{k}"], state[f"lattice_{k}"],
                          species=state.get(f"species_{k}"))
        done.append(DilutedRound(
            packing, np.asarray(state[f"start_index_{k}"], np.int64), int(values["n_removed"]),
            values["phi_diluted"], bool(values["converged"]), int(values["n_steps"]),
            int(values["n_rejected"]), values["wall_seconds"], values["cpu_seconds"]))
    return done


#: per-(seed, round) variables of :func:`diluted_summary`
SUMMARY_VARIABLES = ("phi", "phi_no_rattlers", "rattler_fraction", "z_mean", "strict", "collective",
                     "n_removed", "N", "T", "phi_diluted", "converged")


def diluted_summary(packing_paths, verdict_paths) -> xr.Dataset:
    """One Dataset over (seed, round) of the diluted-MRJ packings and their jamming verdicts.

    ``verdict_paths[k]`` (``hardpack verify`` output) judges ``packing_paths[k]``. A packing with
    a ``dilution_round`` attribute (written by ``hardpack slp-dilute``) is that round; one without
    is the MRJ start, round 0. Every seed must have the same rounds.

    Variables: ``phi`` (rattlers included, as in Fig. 6), ``phi_no_rattlers`` (the spheres the
    verifier counts as rattlers removed, the paper's "removing the rattlers", Sec. VI),
    ``rattler_fraction``, ``z_mean`` (mean contact number of the rattler-free backbone),
    ``strict`` and ``collective`` (verdicts: 1 jammed, 0 not, -1 not tested), ``n_removed``
    (spheres removed since round 0), ``N``, ``T`` (translational order metric of
    :func:`hardpack.structure.order.translational_order`, NaN unless d = 3), ``phi_diluted``
    (density right after the round's removal, NaN in round 0), ``converged`` (the SLP run's).

    Parameters
    ----------
    packing_paths : sequence of str or os.PathLike
        Packing files (the MRJ starts and the ``hardpack slp-dilute`` rounds), each with a
        ``seed`` attribute.
    verdict_paths : sequence of str or os.PathLike
        Their jamming verdicts, in the same order.

    Returns
    -------
    xarray.Dataset
        The variables above over the dimensions ``seed`` and ``round``; attributes
        ``hardpack_kind`` = "slp_diluted", ``T_convention`` and, when the packings have them,
        ``ensemble``, ``d``, ``fraction``, ``distribution``.

    Raises
    ------
    InvalidInputError
        If there are no packings or not one verdict per packing, a verdict judges another
        packing or has another number of spheres, a (seed, round) is given twice, or some seed
        lacks a round the others have.
    StoreError
        If a file is missing, unreadable or of the wrong kind.
    """
    from hardpack.structure.order import translational_order

    packing_paths, verdict_paths = list(packing_paths), list(verdict_paths)
    judged = load_judged_packings(packing_paths, verdict_paths, "diluted summary")
    cells, attrs = {}, {}
    for path, verdict_path, (ds, packing, verdict) in zip(packing_paths, verdict_paths, judged):
        rattler = np.asarray(verdict["rattler"].values, bool)
        if rattler.shape != (packing.n_particles,):
            raise InvalidInputError(f"{verdict_path} has {rattler.size} spheres, {path} has {packing.n_particles}")
        key = (int(ds.attrs["seed"]), int(ds.attrs.get("dilution_round", 0)))
        if key in cells:
            raise InvalidInputError(f"diluted summary: seed {key[0]}, round {key[1]} given twice ({path})")
        backbone = ball_volume(packing.radii[~rattler], packing.dim).sum()
        cells[key] = {
            "phi": packing.phi, "phi_no_rattlers": float(backbone / packing.volume),
            "rattler_fraction": float(verdict.attrs["rattler_fraction"]), "z_mean": float(verdict.attrs["z_mean"]),
            "strict": int(verdict.attrs["strict"]), "collective": int(verdict.attrs["collective"]),
            "n_removed": int(ds.attrs.get("n_removed_total", 0)), "N": packing.n_particles,
            "T": translational_order(packing) if packing.dim == 3 else math.nan,
            "phi_diluted": float(ds.attrs.get("phi_diluted", math.nan)),
            "converged": int(ds.attrs.get("converged", -1)),
        }
        for name in ("ensemble", "d", "fraction", "distribution_params"):
            if name in ds.attrs:
                attrs.setdefault("distribution" if name == "distribution_params" else name, ds.attrs[name])
    seeds = sorted({s for s, _ in cells})
    rounds = sorted({r for _, r in cells})
    missing = [(s, r) for s in seeds for r in rounds if (s, r) not in cells]
    if missing:
        raise InvalidInputError(f"diluted summary: no packing for (seed, round) {missing}; every seed needs "
                                f"rounds {rounds}")
    data = {name: (("seed", "round"), np.array([[cells[s, r][name] for r in rounds] for s in seeds]))
            for name in SUMMARY_VARIABLES}
    return xr.Dataset(data, coords={"seed": seeds, "round": rounds},
                      attrs={"hardpack_kind": "slp_diluted", **attrs,
                             "T_convention": "hardpack.structure.order.translational_order defaults (7 FCC shells)"})
