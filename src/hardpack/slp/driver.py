"""The sequential-LP loop (Torquato & Jiao 2010, Sec. III.B, with the
overlap handling and termination rule derived here).

Each step solves the LP of :mod:`hardpack.slp.lp` and applies it: M -> (I + eps) M,
x -> (I + eps)(x + u). The linearisation drops a cross term of first order in both eps and u
(derived here), so an accepted step can create small overlaps. Handling (a "hybrid" rule
our prototype found necessary; pure halving stalls):

- worst relative overlap above ``reject_overlap`` (1e-4): reject the step and halve the trust
  region (the paper's rule, Torquato & Jiao 2010, Sec. III.B);
- a smaller overlap: accept and scale the whole packing up just enough to remove it;
- after an accepted step the trust region doubles again (up to the full bounds), and the cell is
  LLL-reduced so the image search stays small.

Termination: the LP-predicted density gain -tr(eps*) at the full trust region falls below ``tol``.
The paper stops at a density increase below 1e-8 (Sec. V.A); our default is 1e-10, one or two
more LPs: at 1e-8 the contact gaps are still ~1e-9 D and the strict LP jamming test of
:func:`hardpack.jamming.verify` (contacts within 1e-6, unjamming threshold 1e-6 D) failed on 3 of
4 smoke packings; continued to 1e-10, two of the three passed (the third holds a near-rattler that
the test moves by 3e-4 D). Below ~1e-12 the predicted gain is at the LP tolerance
(1e-10 on rows of size D^2) and the loop no longer terminates. Terminating on the observed gain
would stop falsely after a rescale or a halving.

Checkpoints: with ``checkpoint``, the state after a step (packing, trust region, step count,
history, elapsed time) is written atomically every ``checkpoint_interval`` seconds
(:mod:`hardpack.io.checkpoint`); a run started again with the same start packing and parameters
resumes there. Every step is a deterministic function of that state (HiGHS is deterministic),
so the resumed run ends exactly where the uninterrupted one does. A 3D N = 2000 run of the full
study takes up to 2000 LPs and hours on a shared machine, longer than a session that may stop it.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.geometry.reduction import lll_reduce
from hardpack.io import checkpoint as ckpt
from hardpack.io import interrupt, packing_to_dataset
from hardpack.slp.lp import Bounds, solve_step

log = logging.getLogger(__name__)

MIN_TRUST_SCALE = 2.0**-30


@dataclass(frozen=True)
class SLPResult:
    """The end state of :func:`run_slp` and how it got there.

    It carries no jamming verdict: an SLP fixed point is only a packing in which no LP step gains
    density, and whether it is collectively or strictly jammed is decided by the LP jamming tests
    (:func:`hardpack.jamming.verify`, ``hardpack verify``), as Torquato & Jiao (2010, Sec. III.C)
    test their packings.

    Attributes
    ----------
    packing : Packing
        The last accepted packing (lattice LLL-reduced, positions wrapped).
    history : xarray.Dataset
        One row per LP along ``lp`` (``hardpack_kind`` = "slp_history"): coordinate ``step``,
        ``phi``, ``predicted_gain``, ``n_constraints``, ``lp_seconds``, ``trust_scale``,
        ``worst_overlap``, ``accepted``.
    converged : bool
        The predicted density gain at full trust region fell below ``tol``.
    n_steps : int
        Rows of the history (accepted and rejected LPs, and the final one).
    n_rejected : int
        LP steps rejected for overlaps above ``reject_overlap``.
    wall_seconds, cpu_seconds : float
        Wall-clock and CPU time, summed over resumed invocations.
    """

    packing: Packing
    history: xr.Dataset
    converged: bool
    n_steps: int
    n_rejected: int
    wall_seconds: float
    cpu_seconds: float

    def to_dataset(self, **attrs) -> xr.Dataset:
        """The last accepted packing as a Dataset with the run's outcome as attributes.

        Parameters
        ----------
        **attrs
            Further attributes (e.g. the protocol parameters and the start file).

        Returns
        -------
        xarray.Dataset
            The packing layout of :func:`hardpack.io.packing_to_dataset` with the attributes
            ``converged``, ``n_steps``, ``n_rejected``, ``wall_seconds``, ``cpu_seconds`` and
            ``attrs``. The LP history is :attr:`history`.
        """
        outcome = dict(converged=self.converged, n_steps=self.n_steps, n_rejected=self.n_rejected,
                       wall_seconds=self.wall_seconds, cpu_seconds=self.cpu_seconds)
        return packing_to_dataset(self.packing, {**attrs, **outcome})


def _reduced(packing: Packing) -> Packing:
    lattice, _ = lll_reduce(packing.lattice)
    return packing.replace(lattice=lattice).wrapped()


def _apply(packing: Packing, strain: np.ndarray, displacement: np.ndarray) -> Packing:
    f = np.eye(packing.dim) + strain
    return Packing((packing.positions + displacement) @ f.T, packing.radii, f @ packing.lattice,
                   species=packing.species, allow_overlap=True)


def run_slp(packing: Packing, alpha: float, bounds: Bounds, deforming: bool = True, tol: float = 1e-10,
            max_steps: int = 2000, reject_overlap: float = 1e-4, progress_every: int = 10,
            method: str = "highs-ipm", checkpoint=None, checkpoint_interval: float = 300.0,
            keep_checkpoint: bool = False) -> SLPResult:
    """Densify ``packing`` by sequential LPs until the predicted density gain is below ``tol``.

    ``alpha``: influence-sphere radius over the pair's mean diameter (gamma_mn = alpha D_mn);
    ``bounds``: full trust-region widths; ``deforming``: symmetric strain (the paper's deforming
    cell) or isotropic shrink only (whose end states the paper reports collectively, not
    strictly, jammed; Sec. III.C); ``method``: the HiGHS
    solver of :func:`hardpack.slp.lp.solve_step`; ``checkpoint``: path of a resumable checkpoint
    (module docstring), removed when the run ends unless ``keep_checkpoint`` (then the caller
    removes it once the result is written). On SIGINT or SIGTERM the run writes its checkpoint
    before the next LP and raises :class:`hardpack.io.interrupt.Interrupted`.

    Torquato & Jiao 2010, Sec. III; the step acceptance and trust-region rules are in the
    module docstring.

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing (the start).
    alpha : float
        Influence-sphere radius over the pair's mean diameter (gamma_mn = alpha D_mn).
    bounds : Bounds
        Full trust-region widths (strain, shear, displacement).
    deforming : bool, default True
        Symmetric strain (the paper's deforming cell) or isotropic shrink only.
    tol : float, default 1e-10
        Convergence: predicted density gain (-Tr eps) below which the run stops, in (0, 1).
    max_steps : int, default 2000
        Most LPs (a positive integer); the result says whether it converged.
    reject_overlap : float, default 1e-4
        Largest relative overlap of an accepted step, in (0, 0.5); above it the step is
        rejected and the trust region halved.
    progress_every : int, default 10
        Log a progress line every this many steps (0: never).
    method : str, default "highs-ipm"
        HiGHS solver of :func:`hardpack.slp.lp.solve_step`.
    checkpoint : str or os.PathLike, optional
        Path of the resumable checkpoint.
    checkpoint_interval : float, default 300.0
        Seconds between checkpoint writes.
    keep_checkpoint : bool, default False
        Leave the checkpoint for the caller to remove.

    Returns
    -------
    SLPResult
        The end packing, the per-LP ``history`` Dataset, ``converged``, step counts and times.

    Raises
    ------
    InvalidInputError
        If ``packing`` is not a periodic sphere packing, ``tol`` or ``reject_overlap`` is out of
        range, ``max_steps`` is not a positive integer, or the trust region shrank below
        MIN_TRUST_SCALE of ``bounds`` without an acceptable step (lower the bounds).
    hardpack.io.interrupt.Interrupted
        On SIGINT or SIGTERM, after the checkpoint is written.
    """
    packing.require_periodic_spheres("SLP")
    if not (0 < tol < 1):
        raise InvalidInputError(f"tol must be in (0, 1), got {tol}")
    if not (0 < reject_overlap < 0.5):
        raise InvalidInputError(f"reject_overlap must be in (0, 0.5), got {reject_overlap}")
    if int(max_steps) != max_steps or max_steps < 1:
        raise InvalidInputError(f"max_steps must be a positive integer, got {max_steps}")
    start, cpu_start = time.perf_counter(), time.process_time()
    current = _reduced(packing)
    scale = 1.0
    converged = False
    n_rejected = 0
    records = []
    first, wall_before, cpu_before = 0, 0.0, 0.0
    fp = ckpt.fingerprint(packing, run="slp", alpha=float(alpha), bounds=[bounds.strain, bounds.shear,
                          bounds.displacement], deforming=bool(deforming), tol=float(tol),
                          reject_overlap=float(reject_overlap), method=method)
    state = None if checkpoint is None else ckpt.load(checkpoint, fp)
    if state is not None:
        current = Packing(state["positions"], state["radii"], state["lattice"],
                          species=state.get("species"))
        scale, first, n_rejected = float(state["scale"]), int(state["next_step"]), int(state["n_rejected"])
        records = [tuple(r) for r in state["records"].tolist()]
        wall_before, cpu_before = float(state["wall_seconds"]), float(state["cpu_seconds"])
    last_save = time.perf_counter()
    with interrupt.deferred():
        if state is not None:  # announced once a signal can no longer stop the run before a save
            log.info("resumed from %s at SLP step %d (phi = %.8f)", checkpoint, first, current.phi)
        for step in range(first, int(max_steps)):
            if interrupt.requested() is not None:
                if checkpoint is not None:
                    _save(checkpoint, fp, current, scale, step, n_rejected, records,
                          wall_before + time.perf_counter() - start, cpu_before + time.process_time() - cpu_start)
                raise interrupt.stop(checkpoint, f"SLP step {step} (phi = {current.phi:.8f})")
            if checkpoint is not None and time.perf_counter() - last_save >= checkpoint_interval:
                _save(checkpoint, fp, current, scale, step, n_rejected, records,
                      wall_before + time.perf_counter() - start, cpu_before + time.process_time() - cpu_start)
                last_save = time.perf_counter()
            sol = solve_step(current, alpha, bounds.scaled(scale), deforming, method=method)
            gain = -sol.trace
            if gain < tol:
                if scale == 1.0:
                    converged = True
                    records.append((step, current.phi, gain, sol.n_constraints, sol.lp_seconds, scale, 0.0, 1))
                    break
                scale = 1.0  # a tiny trust region predicts a tiny gain: retry at full width
                continue
            trial = _apply(current, sol.strain, sol.displacement)
            worst = trial.overlap_report(tol=0.0).overlap
            if worst > reject_overlap:
                n_rejected += 1
                records.append((step, current.phi, gain, sol.n_constraints, sol.lp_seconds, scale, worst, 0))
                scale /= 2
                if scale < MIN_TRUST_SCALE:
                    raise InvalidInputError(
                        f"SLP step {step}: the trust region shrank below {MIN_TRUST_SCALE:g} of the bounds "
                        f"without an acceptable step (worst overlap {worst:.2e}); lower the bounds"
                    )
                continue
            if worst > 0:
                grow = (1.0 + 1e-12) / (1.0 - worst)
                trial = Packing(trial.positions * grow, trial.radii, trial.lattice * grow,
                                species=trial.species, allow_overlap=True)
            current = _reduced(Packing(trial.positions, trial.radii, trial.lattice, species=trial.species))
            records.append((step, current.phi, gain, sol.n_constraints, sol.lp_seconds, scale, max(worst, 0.0), 1))
            scale = min(1.0, 2 * scale)
            if progress_every and step % progress_every == 0:
                log.info("SLP step %d: phi = %.8f, predicted gain %.2e, %d constraints, trust %.3g",
                         step, current.phi, gain, sol.n_constraints, scale)
    cols = list(zip(*records)) if records else [[] for _ in range(8)]
    history = xr.Dataset(
        {
            "phi": ("lp", np.asarray(cols[1], float)),
            "predicted_gain": ("lp", np.asarray(cols[2], float)),
            "n_constraints": ("lp", np.asarray(cols[3], np.int64)),
            "lp_seconds": ("lp", np.asarray(cols[4], float)),
            "trust_scale": ("lp", np.asarray(cols[5], float)),
            "worst_overlap": ("lp", np.asarray(cols[6], float)),
            "accepted": ("lp", np.asarray(cols[7], np.int8)),
        },
        coords={"step": ("lp", np.asarray(cols[0], np.int64))},
        attrs={"hardpack_kind": "slp_history"},
    )
    if checkpoint is not None and not keep_checkpoint:
        ckpt.remove(checkpoint)
    return SLPResult(
        packing=current, history=history, converged=converged, n_steps=len(records),
        n_rejected=n_rejected,
        wall_seconds=wall_before + time.perf_counter() - start,
        cpu_seconds=cpu_before + time.process_time() - cpu_start,
    )


def _save(path, fp, packing: Packing, scale, next_step, n_rejected, records, wall, cpu) -> None:
    state = {"positions": packing.positions, "radii": packing.radii, "lattice": packing.lattice,
             "scale": scale, "next_step": next_step, "n_rejected": n_rejected,
             "records": np.asarray(records, dtype=float).reshape(-1, 8),
             "wall_seconds": wall, "cpu_seconds": cpu}
    if packing.species is not None:
        state["species"] = packing.species
    ckpt.save(path, fp, state)
