"""Lubachevsky-Stillinger compression of hard ellipsoids (3D) and ellipses (2D).

Event-driven MD with rotation and growing semiaxes (Donev 2006, dissertation sec. 3.5; kernels and
physics in :mod:`hardpack.md._ellipsoid_kernel`), run window by window exactly as the sphere
compression (:mod:`hardpack.md.compress`): translational and angular velocities rescaled to
kT = 1 each at every synchronisation of a growing run
(:meth:`hardpack.md.ellipsoid_engine.EllipsoidEngine.rescale_velocities`), the reduced pressure
of each window from the collision virial, stop criteria (:class:`hardpack.md.StopCriteria`),
checkpoint/resume bit for bit and progress lines.

Conventions: masses 1, spherically symmetric moments of inertia
(:func:`hardpack.md.ellipsoid_engine.moments_of_inertia`), kT = 2 (KE_trans + KE_rot) /
((d + d_rot) N) with d_rot = 3 in 3D and 1 in 2D. Every semiaxis grows at one relative rate,
a(t) = a(0) (1 + kappa t); the growth rate Gamma = d<D>/dt / sqrt(kT/m) has the sphere engine's
meaning with D the diameter of the volume-equivalent sphere, D = 2 (prod_k a_k)^(1/d), so
kappa = Gamma / (2 <(prod a)^(1/d)>) and spheres run exactly as in the sphere engine.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import DEFAULT_OVERLAP_TOL, Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.io import checkpoint as ckpt
from hardpack.md._ellipsoid_kernel import EPS_F
from hardpack.md.compress import StopCriteria, _check_run_options, default_window, run_windows, timeseries_dataset
from hardpack.md.ellipsoid_engine import EllipsoidEngine, rotational_dof
from hardpack.md.simulation import OverlapError, Simulation, check_start_configuration, maxwell_boltzmann

log = logging.getLogger("hardpack.md")


def check_ellipsoid_packing(packing: Packing) -> None:
    """Refuse packings the ellipsoid engine cannot run (other shapes, sheared cells, fewer than 2
    particles in a periodic cell, overlaps, particles outside the walls or the container).

    Parameters
    ----------
    packing : Packing
        The start packing.

    Raises
    ------
    InvalidInputError
        If the ellipsoid engine cannot run it.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError(f"expected a hardpack Packing, got {type(packing).__name__}")
    if packing.shape.kind != "ellipsoid":
        raise InvalidInputError(f"the ellipsoid MD engine runs ellipsoids or ellipses; this packing "
                                f"holds {packing.shape.name} (use hardpack.md.compress for spheres)")
    if not packing.is_orthorhombic:
        raise InvalidInputError("the ellipsoid MD engine supports orthorhombic (diagonal) periodic "
                                "cells only; this lattice is sheared: pass a diagonal lattice")
    check_start_configuration(packing)


def random_angular_velocities(n: int, d: int, inertia: np.ndarray, seed) -> np.ndarray:
    """Maxwell-Boltzmann angular velocities at kT = 1 (omega_k ~ N(0, 1/I)), zero total angular
    momentum not enforced (a periodic box does not conserve it, a container exchanges none with the
    particles but need not start without); (n, 3) in 3D, (n,) in 2D.

    Parameters
    ----------
    n : int
        Number of particles.
    d : int
        Dimension, 2 or 3.
    inertia : numpy.ndarray of float, shape (n,)
        Moments of inertia (:func:`hardpack.md.ellipsoid_engine.moments_of_inertia`).
    seed : int or numpy.random.SeedSequence or None
        Seed of :func:`numpy.random.default_rng`.

    Returns
    -------
    numpy.ndarray of float, shape (n, 3) in 3D, (n,) in 2D
        Lab-frame angular velocities.
    """
    rng = np.random.default_rng(seed)
    w = rng.standard_normal((n, rotational_dof(d))) / np.sqrt(inertia)[:, None]
    return w[:, 0] if d == 2 else w


class EllipsoidSimulation(Simulation):
    """State of one ellipsoid run (the sphere :class:`hardpack.md.simulation.Simulation` with the
    ellipsoid engine, its temperature and its packing).

    Parameters
    ----------
    packing : Packing
        The start packing of ellipsoids or ellipses (:func:`check_ellipsoid_packing`).
    velocities : numpy.ndarray of float, shape (N, d)
        Start velocities in the packing's order (m = 1).
    angular_velocities : numpy.ndarray of float, shape (N, 3) in 3D, (N,) in 2D
        Start angular velocities in the lab frame.
    growth_rate : float
        Growth rate of the semiaxes, as the sphere Simulation's.
    overlap_tol : float, optional
        Relative overlap above which a window's end state is refused.
    eps_f : float, optional
        Trace tolerance of the engine.
    """

    def __init__(self, packing: Packing, velocities: np.ndarray, angular_velocities: np.ndarray,
                 growth_rate: float, overlap_tol: float = DEFAULT_OVERLAP_TOL, eps_f: float = EPS_F):
        self._setup(packing, growth_rate, overlap_tol)
        shape = packing.shape
        self.engine = EllipsoidEngine(self._engine_positions(packing), velocities, shape.semiaxes, shape.orientations,
                                      angular_velocities, self.box, eps_f=eps_f,
                                      boundary=None if self.boundary.kind == "periodic" else self.boundary)
        self.contacts = None

    def _inverse(self) -> np.ndarray:
        inv = np.empty(self.n, dtype=np.int64)
        inv[self.perm] = np.arange(self.n)
        return inv

    def packing(self) -> Packing:
        """The current configuration in the caller's order, centres wrapped into the box, not
        checked for overlaps (callers check it with :meth:`Packing.overlap_report`, the
        Perram-Wertheim potential)."""
        inv = self._inverse()
        eng = self.engine
        pos = self._wrapped_positions(inv)
        shape = Ellipsoids(eng.semiaxes[inv].copy(), eng.orientations[inv].copy())
        return Packing(pos, lattice=self.lattice, species=self.species, shape=shape, boundary=self.boundary,
                       overlap_tol=self.overlap_tol, allow_overlap=True)

    def _check_walls(self, res) -> None:
        """Raise :class:`OverlapError` when a particle crosses a wall by more than the tolerance
        (:meth:`hardpack.geometry.packing.Packing.containment_report`: the exact support point
        along a flat wall's normal, the exact farthest point from a container's centre)."""
        report = self.packing().containment_report(self.overlap_tol)
        if report.n_outside:
            raise OverlapError(f"at the end of window {self.windows - 1}: {report} (caller's order) > "
                               f"tolerance {self.overlap_tol:g}")

    def angular_velocities(self) -> np.ndarray:
        """Lab-frame angular velocities in the caller's particle order.

        Returns
        -------
        numpy.ndarray of float, shape (N, 3) in 3D, (N,) in 2D
            A copy.
        """
        return self.engine.angular_velocities[self._inverse()].copy()

    def state(self) -> dict:
        """The sphere run state and the engine's thermostat counts
        (:meth:`hardpack.md.ellipsoid_engine.EllipsoidEngine.rescale_velocities`)."""
        return super().state() | {"rescalings": self.engine.rescalings.copy()}

    def restore(self, state: dict) -> None:
        """Load a :meth:`state` (a checkpoint without thermostat counts starts them at 0).

        See :meth:`hardpack.md.simulation.Simulation.restore` for the parameters and the return value.

        Raises
        ------
        InvalidInputError
            If the state is of another system size.
        """
        super().restore(state)
        self.engine.rescalings[:] = np.asarray(state.get("rescalings", np.zeros(3)), dtype=np.int64)

    def run_window(self, coll_target: int, target_phi: float | None = None) -> dict:
        """As :meth:`hardpack.md.simulation.Simulation.run_window` (parameters, record, errors); the
        kT fields are the translational temperature 2 KE_trans / (d N), at the end of the window
        and averaged over it.
        """
        return super().run_window(coll_target, target_phi)


@dataclass
class EllipsoidCompressResult:
    """Final ellipsoid packing, final velocities and angular velocities (m = 1, kT = 1), the
    per-window time series and the run stats.

    Attributes
    ----------
    packing : Packing
        The final packing.
    velocities : numpy.ndarray of float, shape (N, d)
        Final velocities.
    angular_velocities : numpy.ndarray of float, shape (N, 3) in 3D, (N,) in 2D
        Final lab-frame angular velocities.
    timeseries : xarray.Dataset
        One record per window (:func:`hardpack.md.compress.timeseries_dataset`).
    stats : dict
        Run statistics (phi, Z, stop reason, collisions, ...).
    """

    packing: Packing
    velocities: np.ndarray
    angular_velocities: np.ndarray
    timeseries: xr.Dataset
    stats: dict = field(default_factory=dict)

    def to_dataset(self) -> xr.Dataset:
        """The final packing as a Dataset (:func:`hardpack.io.store.packing_to_dataset`) with the
        stats as attributes and the final velocities and angular velocities as variables."""
        from hardpack.io.store import packing_to_dataset

        extra = {"velocity": (("particle", "dim"), self.velocities)}
        if self.packing.dim == 2:
            extra["angular_velocity"] = (("particle",), self.angular_velocities)
        else:
            extra["angular_velocity"] = (("particle", "rotation_axis"), self.angular_velocities)
        return packing_to_dataset(self.packing, attrs=self.stats, extra=extra)

    def save(self, packing_path, timeseries_path=None, config=None):
        """Write the packing (stats as attributes) and optionally the time series, atomically with
        provenance; the velocities are not written (:meth:`to_dataset` has them). Parameters as
        :meth:`hardpack.md.compress.CompressResult.save`.
        """
        from hardpack.io import save_packing, write_dataset

        save_packing(self.packing, packing_path, attrs=self.stats, config=config, seed=self.stats.get("seed"))
        if timeseries_path is not None:
            write_dataset(self.timeseries, timeseries_path, config=config, seed=self.stats.get("seed"))


def _fingerprint(packing: Packing, **params) -> str:
    shape = packing.shape
    return ckpt.fingerprint(_FingerprintView(packing.positions, shape.semiaxes, shape.orientations,
                                             packing.lattice), **params)


@dataclass
class _FingerprintView:
    """What :func:`hardpack.io.checkpoint.fingerprint` hashes (positions, radii, lattice): the
    semiaxes and orientations stand in for the radii."""

    positions: np.ndarray
    semiaxes: np.ndarray
    orientations: np.ndarray
    lattice: np.ndarray

    @property
    def radii(self) -> np.ndarray:
        return np.concatenate([self.semiaxes.ravel(), np.asarray(self.orientations, dtype=float).ravel()])


def compress_ellipsoids(packing: Packing, growth_rate: float, seed: int, stop: StopCriteria | None = None,
                        checkpoint=None, progress=None, *, window: float | None = None,
                        checkpoint_interval: float = 300.0, progress_interval: float = 10.0,
                        overlap_tol: float = DEFAULT_OVERLAP_TOL, final_growth_rate: float | None = None,
                        switch_pressure: float = 1e3, eps_f: float = EPS_F,
                        keep_checkpoint: bool = False) -> EllipsoidCompressResult:
    """LS compression of an ellipsoid or ellipse packing (module docstring); the arguments mean
    what they mean for :func:`hardpack.md.compress` (no contact forces).

    Parameters
    ----------
    packing : Packing
        Ellipsoids (3D) or ellipses (2D) without overlaps: N >= 2 in a periodic orthorhombic cell, or
        N >= 1 between hard flat walls or inside a spherical container (Donev 2006, sec. 3.2.2.1
        and Ch. 7; the wall events of :mod:`hardpack.md._ellipsoid_kernel`; the window records then
        hold ``Z_wall``, the pressure on the walls, and ``wall_collisions``).
    growth_rate : float
        Gamma (module docstring), finite.
    seed : int
        Non-negative seed of the Maxwell-Boltzmann velocities and angular velocities.
    stop : StopCriteria, optional
        Default: reduced pressure 1e12.
    checkpoint : path, optional
        Resumable checkpoint, written every ``checkpoint_interval`` seconds at points where the
        continuation is bit-identical, and on SIGINT / SIGTERM.
    progress : callable, optional
        Receives each window's record.
    window : float, optional
        Collisions per particle between synchronisations (default :func:`default_window`).
    checkpoint_interval, progress_interval : float
        Seconds between checkpoints and between progress log lines.
    overlap_tol : float
        Relative overlap tolerance (1 - mu) checked at every synchronisation and at the end.
    final_growth_rate, switch_pressure : float
        Slow final stage from the first window with Z >= switch_pressure on.
    eps_f : float
        Tolerance on the Hermite interpolation error of the trace event location (default 1e-4,
        Donev 2006, sec. 3.5.1).
    keep_checkpoint : bool
        Leave the checkpoint for the caller to remove.

    Returns
    -------
    EllipsoidCompressResult

    Raises
    ------
    InvalidInputError
        Invalid packing or parameters (as :func:`hardpack.md.compress`).
    OverlapError
        Overlap beyond ``overlap_tol`` at a synchronisation point or at the end.
    """
    check_ellipsoid_packing(packing)
    if not (math.isfinite(eps_f) and 0 < eps_f < 1):
        raise InvalidInputError(f"eps_f must be in (0, 1), got {eps_f!r}")
    stop = _check_run_options(packing, growth_rate, seed, stop, final_growth_rate, switch_pressure, window)
    n, d = packing.n_particles, packing.dim

    def stage_window(rate: float) -> float:
        return default_window(rate, d) if window is None else float(window)

    from hardpack.md.ellipsoid_engine import moments_of_inertia

    seeds = np.random.SeedSequence(seed).spawn(2)
    inertia = moments_of_inertia(packing.shape.semiaxes)
    if packing.boundary.kind == "periodic":
        velocities = maxwell_boltzmann(n, d, seeds[0])
    else:  # the wall takes momentum: no mean to remove (N may be 1); kT is set below
        velocities = np.random.default_rng(seeds[0]).standard_normal((n, d))
    sim = EllipsoidSimulation(packing, velocities,
                              random_angular_velocities(n, d, inertia, seeds[1]), growth_rate,
                              overlap_tol=overlap_tol, eps_f=eps_f)
    sim.engine.rescale_velocities(1.0)
    fp = _fingerprint(packing, growth_rate=float(growth_rate), seed=int(seed), window=window,
                      overlap_tol=overlap_tol, final_growth_rate=final_growth_rate, eps_f=float(eps_f),
                      switch_pressure=float(switch_pressure) if final_growth_rate else None,
                      kind="ellipsoid", boundary=str(packing.boundary))
    reason = run_windows(sim, stop, stage_window, checkpoint, fp, final_growth_rate=final_growth_rate,
                         switch_pressure=switch_pressure, progress=progress, progress_interval=progress_interval,
                         checkpoint_interval=checkpoint_interval, label="ellipsoids: ")

    final = sim.packing()
    report = final.overlap_report(overlap_tol)
    if report.n_overlapping:
        raise OverlapError(f"the final ellipsoid packing has overlaps beyond {overlap_tol:g}: {report}")
    walls = final.containment_report(overlap_tol)
    if walls.n_outside:
        raise OverlapError(f"the final ellipsoid packing crosses a wall beyond {overlap_tol:g}: {walls}")
    final = final.replace(allow_overlap=False)
    last = {k: (sim.records[k][-1] if sim.records[k] else float("nan")) for k in ("Z", "phi_J_est")}
    stats = {
        "protocol": "lubachevsky_stillinger" if final_growth_rate is None
        else "lubachevsky_stillinger_two_stage",
        "shape_kind": "ellipsoid", "growth_rate": float(growth_rate), "seed": int(seed),
        "stop_reason": reason, "Z": float(last["Z"]), "phi": float(final.phi),
        "phi_J_est": float(last["phi_J_est"]), "collisions": int(sim.collisions),
        "events": int(sim.events), "windows": int(sim.windows), "md_time": float(sim.time),
        "wall_time": float(sim.wall_time), "window_collisions_per_particle": stage_window(growth_rate),
        "overlap_tol": overlap_tol, "eps_f": float(eps_f),
        # thermostat: rescalings with two factors, with one, left out (EllipsoidEngine.rescale_velocities)
        "rescalings_two_factors": int(sim.engine.rescalings[0]),
        "rescalings_one_factor": int(sim.engine.rescalings[1]),
        "rescalings_left_out": int(sim.engine.rescalings[2]),
        "max_overlap": float(report.overlap), "n_overlapping": int(report.n_overlapping),
        "overlap_check": "passed", "mass": 1.0, "kT": 1.0,
        "moment_of_inertia": "spherically symmetric: (2/15)(a^2+b^2+c^2) in 3D, (a^2+b^2)/4 in 2D",
    }
    if final.boundary.kind != "periodic":
        stats.update({"max_wall_overlap": float(walls.overlap), "containment_check": "passed",
                      "Z_wall": float(sim.records["Z_wall"][-1]) if sim.records["Z_wall"] else float("nan")})
    if final_growth_rate is not None:
        stats.update({"final_growth_rate": float(final_growth_rate), "switch_pressure": float(switch_pressure)})
    ts_attrs = {k: stats[k] for k in ("growth_rate", "seed", "stop_reason", "final_growth_rate",
                                      "switch_pressure") if k in stats}
    ts = timeseries_dataset(sim, ts_attrs | {"N": n, "d": d, "shape_kind": "ellipsoid"})
    if checkpoint is not None and not keep_checkpoint:
        ckpt.remove(checkpoint)
    return EllipsoidCompressResult(final, sim.velocities(), sim.angular_velocities(), ts, stats)
