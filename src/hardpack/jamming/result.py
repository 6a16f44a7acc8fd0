"""JammingResult: the verdict of :func:`hardpack.jamming.verify` and its xarray form."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from hardpack.jamming.contacts import ContactNetwork
from hardpack.jamming.forces import Forces, Statics
from hardpack.jamming.highs import FALLBACKS
from hardpack.jamming.ideal import TestOutcome
from hardpack.jamming.sequential import SequentialOutcome

CATEGORIES = ("local", "collective", "strict")
ADVERBS = {"local": "locally", "collective": "collectively", "strict": "strictly"}
#: codes of a test's verdict in the dataset's attributes


class Verdict(enum.IntEnum):
    """A jamming test's verdict as stored in datasets (netCDF has no booleans with a "not run")."""

    JAMMED = 1
    NOT_JAMMED = 0
    NOT_RUN = -1
    UNDETERMINED = -2  # the test ran but could not decide (the reason is stored beside it)

    @classmethod
    def of(cls, jammed: bool | None, undetermined: bool = False) -> Verdict:
        """The code of a verdict (``jammed`` None: the test was not run).

        Parameters
        ----------
        jammed : bool or None
            The test's verdict, None if it was not run.
        undetermined : bool, default False
            The test ran but could not decide; takes precedence over ``jammed``.

        Returns
        -------
        Verdict
            UNDETERMINED, NOT_RUN, JAMMED or NOT_JAMMED.
        """
        if undetermined:
            return cls.UNDETERMINED
        return cls.NOT_RUN if jammed is None else cls.JAMMED if jammed else cls.NOT_JAMMED


@dataclass
class JammingResult:
    """Everything :func:`verify` measured. ``None`` marks a test that was not run.

    A packing with a jammed backbone counts as jammed (Donev 2006, sec. 4.2.4.1); the verdicts
    of the collective and strict tests are the properties :attr:`collective` and :attr:`strict`.

    Attributes
    ----------
    params : dict
        The settings of the run (boundary, method, tolerances, seed, tests, mean diameter; the
        sequential test's settings or None; ``force_delta`` and ``force_near_contacts`` when the
        forces come from the nearest jamming point).
    network : ContactNetwork
        All contacts within delta; when the forces come from the nearest jamming point, the
        contacts within delta plus the near contacts that carry force there.
    local : bool
        True when the local test leaves a non-empty backbone (locally jammed).
    local_rattler : numpy.ndarray
        (N,) bool, the particles the local test removed.
    local_escape : numpy.ndarray
        (N,) local escape displacement |dr_i| of each particle tested by an LP, NaN where not
        measured (:func:`remove_rattlers`).
    collective_test, strict_test : TestOutcome or SequentialOutcome or None
        Outcome of the collective and strict tests (ideal, Algorithm 13, or sequential,
        Algorithm 14); None when not run.
    rattler : numpy.ndarray
        (N,) bool, particles outside the backbone (local rattlers, plus rattling clusters the
        collective test removed when it found a jammed backbone).
    forces : Forces
        The backbone self-stress (``forces.forces``, on the contacts of ``network``).
    statics : Statics
        Contact numbers, isostaticity and pressures of the backbone (:func:`statics`).
    volume : float
        Volume of the cell or container.
    md_pressure : float or None
        Reduced pressure PV/(NkT) of the generator, if given to :func:`verify`.
    ellipse_slope : float or None
        For periodic disks with a self-stress, s_phi of the ellipses made from them
        (:func:`hardpack.jamming.near_sphere.ellipse_slope`, Donev 2006 Eq. 5.29); else None.
    seconds : dict
        Wall time of each stage (contacts, local, collective, strict, forces).
    fallbacks : dict
        How many times each numerical fallback of :data:`FALLBACKS` happened.
    """

    params: dict
    network: ContactNetwork
    local: bool | None
    local_rattler: np.ndarray
    local_escape: np.ndarray
    collective_test: TestOutcome | SequentialOutcome | None
    strict_test: TestOutcome | SequentialOutcome | None
    rattler: np.ndarray
    forces: Forces
    statics: Statics
    volume: float
    md_pressure: float | None = None
    ellipse_slope: float | None = None
    seconds: dict = field(default_factory=dict)
    fallbacks: dict = field(default_factory=lambda: dict.fromkeys(FALLBACKS, 0))

    # ------------------------------------------------------------------ verdicts
    @property
    def collective(self) -> bool | None:
        """None when the test was not run or could not decide (:attr:`undetermined`)."""
        return _verdict(self.collective_test)

    @property
    def strict(self) -> bool | None:
        """None when the test was not run or could not decide (:attr:`undetermined`)."""
        return _verdict(self.strict_test)

    @property
    def undetermined(self) -> dict:
        """{test: reason} of the tests that ran but could not decide."""
        return {name: out.undetermined for name, out in
                (("collective", self.collective_test), ("strict", self.strict_test))
                if out is not None and out.undetermined}

    @property
    def category(self) -> str:
        """The strongest category that holds among the tests run ('not jammed' if none), and the
        first test that could not decide, if any."""
        best = "not jammed"
        for name in CATEGORIES:
            if name in self.undetermined:
                return f"{best}; {name} jamming undetermined"
            value = getattr(self, name)
            if value is None:
                continue
            if not value:
                break
            best = ADVERBS[name] + " jammed"
        return best

    @property
    def verdicts(self) -> dict:
        return {name: getattr(self, name) for name in CATEGORIES}

    # ------------------------------------------------------------------ numbers
    @property
    def z_mean(self) -> float:
        """Mean contact number of the rattler-free backbone."""
        return self.statics.z_mean

    @property
    def isostaticity_gap(self) -> int:
        return self.statics.isostaticity_gap

    @property
    def rattler_fraction(self) -> float:
        return float(self.rattler.mean())

    @property
    def pressure_ratio(self) -> float | None:
        """Free-volume pressure from forces and gaps over the MD's reduced pressure."""
        if self.md_pressure is None or not np.isfinite(self.statics.pressure_free_volume):
            return None
        return float(self.statics.pressure_free_volume / self.md_pressure)

    def unjamming(self, test: str) -> dict:
        """Size of the unjamming motion a test found, in mean diameters (0 when none).

        Ideal test: the first motion that displaced something (LP rays stop at the box, so the size is
        the box's); sequential test: the largest mean and largest maximum displacement over the
        loading sequences, and the strain of the sequence with the largest mean displacement.

        Parameters
        ----------
        test : str
            "collective"; any other value means the strict test.

        Returns
        -------
        dict
            ``mean`` and ``max`` of |dr_i| over the particles, in mean diameters, and ``strain``, the
            2-norm of the strain tensor (0 without strain); empty when the test was not run.
        """
        out = self.collective_test if test == "collective" else self.strict_test
        if out is None:
            return {}
        if isinstance(out, SequentialOutcome):
            strain = 0.0 if out.strain is None else float(np.linalg.norm(out.strain, 2))
            return {"mean": max(out.mean_displacement, default=0.0),
                    "max": max(out.max_displacement, default=0.0), "strain": strain}
        size = np.linalg.norm(out.motion, axis=1) / self.params["mean_diameter"]
        return {"mean": float(size.mean()), "max": float(size.max(initial=0.0)),
                "strain": out.strain_norm}

    def summary(self) -> str:
        """A few human-readable lines."""
        p, s, net = self.params, self.statics, self.network
        lines = [
            (f"verdict: {self.category}  (local={_yn(self.local)}, collective={_yn(self.collective)}, "
             f"strict={_yn(self.strict)}; method={p['method']}, delta={p['delta']:g}, "
             f"dr_large={p['dr_large']:.3g}, seed={p['seed']})"),
            *(f"{name} test undetermined: {reason}" for name, reason in self.undetermined.items()),
            (f"N={self.network.n_particles}, contacts={self.network.n_contacts}, "
             f"rattlers={int(self.rattler.sum())} ({100 * self.rattler_fraction:.2f}%), "
             f"backbone N_b={s.n_backbone}, M_b={s.n_contacts}, Z={s.z_mean:.4f}"),
            (f"isostaticity: M_b - N_f - 1 = {s.isostaticity_gap} (collective, N_f = {s.n_dof_collective}), "
             f"{s.isostaticity_gap_strict} (strict, N_f = {s.n_dof_strict})"),
        ]
        if net.n_wall_contacts:
            reaction = f" with total reaction {s.wall_force:.4g} (forces of mean 1)" if self.forces.exists else ""
            lines.append(f"{self.params.get('boundary', 'walls')}: {net.n_wall_contacts} wall contacts, "
                         f"{s.n_wall_contacts} of them in the backbone (among M_b){reaction}")
        if not self.local:
            lines.append(f"no backbone: all {self.network.n_particles} particles are rattlers, so "
                         "nothing is jammed (no collective or strict LP was needed)")
        for name, count in self.fallbacks.items():
            if count:
                lines.append(f"numerical fallback {name}: {count} ({FALLBACKS[name]})")
        for test in ("collective", "strict"):
            u = self.unjamming(test)
            if u:
                lines.append(
                    f"{test} unjamming displacement / D: mean {u['mean']:.3g}, max {u['max']:.3g}"
                    f", strain {u['strain']:.3g}"
                )
        if "force_near_contacts" in p:
            lines.append(
                f"forces of the nearest jamming point: {p['force_near_contacts']} near contacts "
                f"(within delta = {p['force_delta']:g}) close there and carry force"
            )
        if self.forces.exists:
            lines.append(
                f"forces: min/mean {self.forces.min_force:.3g}, max |imbalance| "
                f"{np.abs(self.forces.imbalance).max():.2e}; virial p V / (mean f) = "
                f"{s.pressure_virial * self.volume:.4g}; jamming gap mu* = {s.jamming_gap:.3e}"
            )
        if self.md_pressure is not None:
            lines.append(
                f"pressure: free-volume from forces {s.pressure_free_volume:.4g} vs MD "
                f"{self.md_pressure:.4g} (ratio {self.pressure_ratio})"
            )
        return "\n".join(lines)

    # ------------------------------------------------------------------ dataset
    def to_dataset(self) -> xr.Dataset:
        """Per-particle, per-contact and scalar results (dims 'particle', 'contact', 'dim').

        Wall contacts (hard walls, container) have ``contact_wall`` >= 0 (the wall's number, -1 for a
        pair; :mod:`hardpack.jamming.contacts`), ``contact_j`` = ``contact_i`` and ``contact_gap``
        h / r - 1; their ``force`` is the wall's reaction; attributes ``n_wall_contacts``,
        ``n_backbone_wall_contacts``, ``wall_force`` (sum of the reactions) and ``boundary``.
        Verdict attributes ``local``, ``collective``, ``strict``: the codes of :class:`Verdict` (1 jammed,
        0 not jammed, -1 not run, -2 undetermined, the reason in ``<test>_undetermined``); ``fallback_<name>``: the
        count of each numerical fallback (:data:`FALLBACKS`), 0 when it did not happen."""
        net, d = self.network, self.network.dim
        data = {
            "contact_i": (("contact",), net.i),
            "contact_j": (("contact",), net.j),
            "contact_shift": (("contact", "dim"), net.shift),
            "contact_wall": (("contact",), net.wall),
            "contact_gap": (("contact",), net.distance / net.contact_distance - 1.0),  # h/r - 1 for walls
            "force": (("contact",), self.forces.forces),
            "rattler": (("particle",), self.rattler.astype(np.int8)),
            "local_rattler": (("particle",), self.local_rattler.astype(np.int8)),
            "local_escape": (("particle",), self.local_escape),
            "force_imbalance": (("particle", "dim"), self.forces.imbalance),
            "stress": (("dim", "dim2"), self.statics.stress),
        }
        for name, out in (("collective", self.collective_test), ("strict", self.strict_test)):
            if out is None:
                continue
            data[f"{name}_displacement"] = (("particle",), out.displacement)
            data[f"{name}_motion"] = (("particle", "dim"), _or_zeros(out.motion, net.n_particles, d))
            if out.strain is not None:
                data[f"{name}_strain"] = (("dim", "dim2"), out.strain)
            if isinstance(out, TestOutcome):
                data[f"{name}_backbone"] = (("particle",), out.backbone.astype(np.int8))
        s = self.statics
        attrs = dict(
            hardpack_kind="jamming", verdict=self.category,
            **{k: int(Verdict.of(v, k in self.undetermined)) for k, v in self.verdicts.items()},
            **{f"{k}_undetermined": reason for k, reason in self.undetermined.items()},
            **{f"fallback_{k}": int(v) for k, v in self.fallbacks.items()},
            **{k: v for k, v in self.params.items() if v is not None},
            N=net.n_particles, d=d, n_contacts=net.n_contacts, n_wall_contacts=net.n_wall_contacts,
            n_backbone_wall_contacts=s.n_wall_contacts, wall_force=s.wall_force,
            n_rattlers=int(self.rattler.sum()),
            rattler_fraction=self.rattler_fraction, n_backbone=s.n_backbone,
            n_backbone_contacts=s.n_contacts, z_mean=s.z_mean,
            isostaticity_gap=s.isostaticity_gap, isostaticity_gap_strict=s.isostaticity_gap_strict,
            forces_exist=int(self.forces.exists), min_force=self.forces.min_force,
            pressure_virial=s.pressure_virial, jamming_gap=s.jamming_gap,
            pressure_free_volume=s.pressure_free_volume, volume=self.volume,
        )
        if self.md_pressure is not None:
            attrs["md_pressure"] = self.md_pressure
        if self.ellipse_slope is not None:
            attrs["ellipse_slope"] = self.ellipse_slope
        for test in ("collective", "strict"):
            for key, value in self.unjamming(test).items():
                attrs[f"{test}_unjamming_{key}"] = value
        for key, value in self.seconds.items():
            attrs[f"seconds_{key}"] = value
        return xr.Dataset(data, attrs=attrs)


def _verdict(out) -> bool | None:
    return None if out is None or out.undetermined else bool(out.jammed)


def _or_zeros(arr, n, d):
    return np.zeros((n, d)) if arr is None else arr


def _yn(value) -> str:
    return "-" if value is None else ("yes" if value else "no")
