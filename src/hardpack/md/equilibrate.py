"""Equilibrium (NVE, fixed phi) runs: the reduced pressure Z with a block-average error bar.

With Gamma = 0 collisions conserve energy and momentum exactly, so no rescaling is done and kT
stays 1. After ``n_equilibration`` collisions the run is cut into ``n_blocks`` blocks of equal
numbers of collisions; each block gives Z = 1 + sum r_ij . J_ij / (2 * integral of KE dt)
(the collisional stress averaged over a time window, Donev 2006, dissertation ch. 3, in its
reduced-pressure form, which we derive), summed over the short
MD windows that make up the block (so that a checkpoint can be written within a block), and the
error is the standard error of the block means, std/sqrt(n_blocks)
(blocks of many collisions per particle are much longer than the pressure's correlation time).

With ``checkpoint`` the run is resumable like :func:`hardpack.md.compress`: its state is saved at
checkpoint-ready windows every ``checkpoint_interval`` seconds and on SIGINT or SIGTERM
(:mod:`hardpack.io.interrupt`), and a run started again with the same arguments ends with the
same block values, bit for bit.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError, check_seed
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, Packing
from hardpack.io import checkpoint as ckpt
from hardpack.io import interrupt
from hardpack.md.simulation import Simulation, check_packing, maxwell_boltzmann

log = logging.getLogger("hardpack.md")


@dataclass
class EquilibriumResult:
    """Mean reduced pressure Z +- Z_err (standard error over blocks) at volume fraction phi.

    Attributes
    ----------
    Z : float
        Mean of the block values of Z = pV/(NkT).
    Z_err : float
        Standard error of the block means, std / sqrt(n_blocks).
    Z_blocks : numpy.ndarray, shape (n_blocks,)
        The block values.
    phi : float
        Volume fraction.
    collisions : int
        Collisions after equilibration.
    md_time : float
        MD time after equilibration.
    wall_time : float
        Wall-clock seconds of the whole run.
    packing : Packing
        The final configuration.
    velocities : numpy.ndarray, shape (N, d)
        The final velocities.
    equilibration : int
        Collisions discarded before the blocks.
    """

    Z: float
    Z_err: float
    Z_blocks: np.ndarray
    phi: float
    collisions: int
    md_time: float
    wall_time: float
    packing: Packing
    velocities: np.ndarray
    equilibration: int = 0

    def to_dataset(self, **attrs) -> xr.Dataset:
        """The block values as a Dataset (``hardpack_kind = "md_eos"``; Z, Z_err, phi, N, d and
        the run's counts as attributes, plus ``attrs``).

        Parameters
        ----------
        **attrs
            Further attributes (e.g. the protocol parameters).

        Returns
        -------
        xarray.Dataset
            ``Z_block(block)`` with the attributes ``hardpack_kind``, ``Z``, ``Z_err``, ``phi``,
            ``N``, ``d``, ``collisions``, ``equilibration``, ``md_time``, ``wall_time`` and
            ``attrs``.
        """
        ds = xr.Dataset({"Z_block": (("block",), self.Z_blocks)},
                        coords={"block": np.arange(len(self.Z_blocks))})
        ds.attrs.update(hardpack_kind="md_eos", Z=self.Z, Z_err=self.Z_err, phi=self.phi,
                        N=self.packing.n_particles, d=self.packing.dim, collisions=self.collisions,
                        equilibration=self.equilibration, md_time=self.md_time, wall_time=self.wall_time, **attrs)
        return ds


def equilibrate(packing: Packing, seed: int, n_collisions: int, *, n_blocks: int = 20,
                n_equilibration: int | None = None,
                overlap_tol: float = DEFAULT_OVERLAP_TOL, checkpoint=None,
                checkpoint_interval: float = 300.0, keep_checkpoint: bool = False) -> EquilibriumResult:
    """Run NVE hard-sphere MD at fixed phi and measure Z over ``n_collisions`` collisions.

    n_equilibration: collisions discarded first (default n_collisions // 4).
    checkpoint: resumable checkpoint (module docstring), removed at the end unless
    ``keep_checkpoint`` (then the caller removes it once the result is written).

    Parameters
    ----------
    packing : Packing
        Start configuration: a periodic sphere packing in an orthorhombic cell, N >= 2, without
        overlaps; its phi is kept (Gamma = 0).
    seed : int
        Non-negative seed of the initial Maxwell-Boltzmann velocities.
    n_collisions : int
        Collisions measured (after equilibration), an integer >= n_blocks.
    n_blocks : int, default 20
        Blocks of n_collisions // n_blocks collisions each, an integer >= 2.
    n_equilibration : int, optional
        Collisions discarded first (>= 0); default n_collisions // 4.
    overlap_tol : float, default DEFAULT_OVERLAP_TOL
        Relative overlap tolerance checked at every synchronisation.
    checkpoint : str or os.PathLike, optional
        Path of the resumable checkpoint.
    checkpoint_interval : float, default 300.0
        Seconds between checkpoint writes.
    keep_checkpoint : bool, default False
        Leave the checkpoint for the caller to remove.

    Returns
    -------
    EquilibriumResult
        Z +- Z_err with the block values, phi, the counts and times of the measured part, the
        final packing and velocities; :meth:`EquilibriumResult.to_dataset` stores it.

    Raises
    ------
    InvalidInputError
        If the packing cannot be run (not periodic spheres, sheared cell, fewer than 2
        particles, overlaps), ``seed`` is not a non-negative integer, ``n_blocks`` < 2,
        ``n_collisions`` < n_blocks, or ``n_equilibration`` < 0.
    OverlapError
        If particles overlap beyond ``overlap_tol`` at a synchronisation point (an engine
        failure).
    hardpack.io.interrupt.Interrupted
        On SIGINT or SIGTERM (after the checkpoint is written, when there is one).
    """
    check_packing(packing)
    check_seed(seed)
    if int(n_blocks) != n_blocks or n_blocks < 2:
        raise InvalidInputError(f"n_blocks must be an integer >= 2, got {n_blocks!r}")
    if int(n_collisions) != n_collisions or n_collisions < n_blocks:
        raise InvalidInputError(f"n_collisions must be an integer >= n_blocks, got {n_collisions!r}")
    n_eq = int(n_collisions) // 4 if n_equilibration is None else int(n_equilibration)
    if n_eq < 0:
        raise InvalidInputError(f"n_equilibration must be >= 0, got {n_equilibration!r}")
    sim = Simulation(packing, maxwell_boltzmann(packing.n_particles, packing.dim, seed), 0.0,
                     overlap_tol=overlap_tol)
    block = max(1, int(n_collisions) // int(n_blocks))
    per_window = max(1, round(20 * sim.n))  # keep windows short enough for frequent checks
    fp = ckpt.fingerprint(packing, run="equilibrate", seed=int(seed), n_collisions=int(n_collisions),
                          n_blocks=int(n_blocks), n_equilibration=n_eq, overlap_tol=overlap_tol,
                          window=per_window)
    z: list[float] = []
    partial = np.zeros(3)  # the current block so far: virial, integral of KE dt, collisions
    start_time, start_coll = 0.0, n_eq
    state = None if checkpoint is None else ckpt.load(checkpoint, fp)
    if state is not None:
        z = list(np.atleast_1d(state.pop("Z_blocks")))[:int(state.pop("n_blocks_done"))]
        start_time = float(state.pop("start_time"))
        partial = np.asarray(state.pop("block_partial"), dtype=float)
        sim.restore(state)
    last_save = time.perf_counter()
    with interrupt.deferred():
        if state is not None:  # announced once a signal can no longer stop the run before a save
            log.info("resumed from %s after %d collisions (%d blocks done)", checkpoint, sim.collisions,
                     len(z))
        while len(z) < int(n_blocks):
            if sim.collisions < n_eq:
                sim.run_window(min(per_window, n_eq - sim.collisions))
                start_time, start_coll = sim.time, sim.collisions
            else:
                before = sim.collisions
                rec = sim.run_window(min(per_window, block - int(partial[2])))
                partial += (rec["virial"], rec["ke_integral"], sim.collisions - before)
                if partial[2] >= block:
                    z.append(1.0 + partial[0] / (2.0 * partial[1]) if partial[1] > 0.0 else np.inf)
                    partial[:] = 0.0
            if len(z) == int(n_blocks):
                break  # done: a signal received during the last windows stops nothing
            if checkpoint is not None and sim.checkpoint_ready and (
                    interrupt.requested() is not None or time.perf_counter() - last_save >= checkpoint_interval):
                ckpt.save(checkpoint, fp, sim.state() | {"Z_blocks": np.asarray(z, dtype=float),
                                                          "n_blocks_done": len(z), "start_time": start_time,
                                                          "block_partial": partial.copy()})
                last_save = time.perf_counter()
            if interrupt.requested() is not None and (checkpoint is None or sim.checkpoint_ready):
                raise interrupt.stop(checkpoint, f"{sim.collisions} of {n_eq + block * int(n_blocks)} "
                                                 "collisions")
    z = np.asarray(z)
    if checkpoint is not None and not keep_checkpoint:
        ckpt.remove(checkpoint)
    return EquilibriumResult(
        Z=float(z.mean()), Z_err=float(z.std(ddof=1) / math.sqrt(len(z))), Z_blocks=z,
        phi=sim.phi(), collisions=sim.collisions - start_coll, md_time=sim.time - start_time,
        wall_time=sim.wall_time, packing=sim.packing(), velocities=sim.velocities(), equilibration=n_eq,
    )
