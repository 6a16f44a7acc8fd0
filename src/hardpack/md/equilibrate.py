"""Equilibrium (NVE, fixed phi) runs: the reduced pressure Z with a block-average error bar.

With Gamma = 0 collisions conserve energy and momentum exactly, so no rescaling is done and kT
stays 1. After ``n_equilibration`` collisions the run is cut into ``n_blocks`` windows of equal
numbers of collisions; each window gives Z = 1 + sum r_ij . J_ij / (2 * integral of KE dt)
(note 000 sec. 2.5), and the error is the standard error of the block means, std/sqrt(n_blocks)
(blocks of many collisions per particle are much longer than the pressure's correlation time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, Packing
from hardpack.md.simulation import Simulation, check_packing, maxwell_boltzmann


@dataclass
class EquilibriumResult:
    """Mean reduced pressure Z +- Z_err (standard error over blocks) at volume fraction phi."""

    Z: float
    Z_err: float
    Z_blocks: np.ndarray
    phi: float
    collisions: int
    md_time: float
    wall_time: float
    packing: Packing
    velocities: np.ndarray


def equilibrate(packing: Packing, seed: int, n_collisions: int, *, n_blocks: int = 20,
                n_equilibration: int | None = None,
                overlap_tol: float = DEFAULT_OVERLAP_TOL) -> EquilibriumResult:
    """Run NVE hard-sphere MD at fixed phi and measure Z over ``n_collisions`` collisions.

    n_equilibration: collisions discarded first (default n_collisions // 4).
    """
    check_packing(packing)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError(f"seed must be a non-negative integer, got {seed!r}")
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
    while sim.collisions < n_eq:
        sim.run_window(min(per_window, n_eq - sim.collisions))
    start_time, start_coll = sim.time, sim.collisions
    z = np.array([sim.run_window(block)["Z"] for _ in range(int(n_blocks))])
    return EquilibriumResult(
        Z=float(z.mean()), Z_err=float(z.std(ddof=1) / math.sqrt(len(z))), Z_blocks=z,
        phi=sim.phi(), collisions=sim.collisions - start_coll, md_time=sim.time - start_time,
        wall_time=sim.wall_time, packing=sim.packing(), velocities=sim.velocities(),
    )
