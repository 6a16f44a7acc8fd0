"""Crystal packings of equal spheres at contact (nearest-neighbour distance 1, radius 1/2).

Unit cells follow the usual crystallographic conventions (conventional cubic cells for SC, BCC,
FCC, diamond; primitive hexagonal cells for triangular, honeycomb, Kagome and HCP). Densities:
square pi/4, triangular pi/sqrt(12) = 0.9069, SC pi/6 = 0.5236, BCC pi sqrt(3)/8 = 0.6802,
FCC = HCP pi/sqrt(18) = 0.7405, diamond pi sqrt(3)/16 = 0.3401, and the checkerboard lattices
D_d (D_4 = 0.6169, D_5 = 0.4653; Conway & Sloane) in any d.
"""

from __future__ import annotations

import itertools
import numbers

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing

_S3 = np.sqrt(3.0)


def _cell(name: str):
    """(lattice with vectors as columns, fractional basis, radius) for a named crystal."""
    if name == "square":
        return np.eye(2), np.zeros((1, 2)), 0.5
    if name == "triangular":
        return np.array([[1.0, 0.5], [0.0, _S3 / 2]]), np.zeros((1, 2)), 0.5
    if name == "honeycomb":
        lat = np.array([[_S3, _S3 / 2], [0.0, 1.5]])
        basis = np.array([[0.0, 0.0], [1 / 3, 1 / 3]])
        return lat, basis, 0.5
    if name == "kagome":
        lat = np.array([[2.0, 1.0], [0.0, _S3]])
        basis = np.array([[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]])
        return lat, basis, 0.5
    if name == "sc":
        return np.eye(3), np.zeros((1, 3)), 0.5
    if name == "bcc":
        a = 2 / _S3
        return a * np.eye(3), np.array([[0, 0, 0], [0.5, 0.5, 0.5]], float), 0.5
    if name == "fcc":
        a = np.sqrt(2.0)
        basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]], float)
        return a * np.eye(3), basis, 0.5
    if name == "hcp":
        c = np.sqrt(8 / 3)
        lat = np.array([[1.0, 0.5, 0.0], [0.0, _S3 / 2, 0.0], [0.0, 0.0, c]])
        basis = np.array([[0, 0, 0], [1 / 3, 1 / 3, 0.5]])
        return lat, basis, 0.5
    if name == "diamond":
        a = 4 / _S3
        fcc = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]], float)
        return a * np.eye(3), np.vstack([fcc, fcc + 0.25]), 0.5
    if name.startswith("hypercubic"):
        d = int(name[len("hypercubic"):])
        return np.eye(d), np.zeros((1, d)), 0.5
    if name[0] == "D" and name[1:].isdigit():
        d = int(name[1:])
        pts = [p for p in itertools.product((0, 1), repeat=d) if sum(p) % 2 == 0]
        # conventional cell of side 2 (integer coordinates), scaled to nearest-neighbour distance 1
        scale = 1 / np.sqrt(2.0)
        return 2 * scale * np.eye(d), np.array(pts, float) / 2, 0.5
    raise InvalidInputError(
        f"unknown lattice {name!r}; choose one of {sorted(LATTICES)} or 'hypercubic<d>' / 'D<d>'"
    )


LATTICES = ("square", "triangular", "honeycomb", "kagome", "sc", "bcc", "fcc", "hcp", "diamond")


def lattice_packing(name: str, reps=1) -> Packing:
    """A crystal of ``name`` with its unit cell repeated ``reps`` times along each lattice vector.

    ``reps`` is a positive integer or a sequence of d of them (whole-valued floats such as 2.0
    are taken as integers; 2.5, 0, -1, True or a sequence of the wrong length are refused).
    Spheres have radius 1/2 and touch their nearest neighbours exactly.

    Parameters
    ----------
    name : str
        One of "square", "triangular", "honeycomb", "kagome" (2D), "sc", "bcc", "fcc", "hcp",
        "diamond" (3D), "hypercubic<d>" or "D<d>" (the checkerboard lattice D_d) in any d.
        Cells are conventional cubic (SC, BCC, FCC, diamond, D_d) or primitive hexagonal
        (triangular, honeycomb, Kagome, HCP); see the module docstring.
    reps : int or sequence of int, default 1
        Repetitions of the unit cell along each lattice vector (one count for all, or d).

    Returns
    -------
    Packing
        A periodic packing of spheres of radius 1/2 (nearest-neighbour distance 1) whose
        lattice is the unit cell scaled by ``reps``.

    Raises
    ------
    InvalidInputError
        If ``name`` is not a known lattice or ``reps`` is not one or d positive whole numbers.
    """
    lat, basis, radius = _cell(name)
    d = lat.shape[0]
    reps = _repetitions(reps, d, name)
    cells = np.array(list(itertools.product(*[range(r) for r in reps])), dtype=float)
    frac = (cells[:, None, :] + basis[None, :, :]).reshape(-1, d) / reps
    big = lat * reps  # scale each column (lattice vector)
    positions = frac @ big.T
    radii = np.full(len(positions), radius)
    return Packing(positions, radii, big)


def _repetitions(reps, d: int, name: str) -> np.ndarray:
    """``reps`` of :func:`lattice_packing` as d positive ints, or InvalidInputError."""
    values = np.atleast_1d(np.asarray(reps, dtype=object))
    if values.ndim != 1 or values.size not in (1, d):
        raise InvalidInputError(
            f"reps must be one repetition count or {d} of them (one per lattice vector of the "
            f"{d}D lattice {name!r}), got {reps!r}")
    counts = []
    for value in values:
        whole = (isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
                 and np.isfinite(float(value)) and float(value).is_integer())
        if not whole or value < 1:
            raise InvalidInputError(
                f"reps must be positive whole numbers of unit cells along the lattice vectors "
                f"(e.g. 2 or (3, 2, 1)), got {reps!r}: {value!r} is not")
        counts.append(int(value))
    return np.broadcast_to(np.array(counts, dtype=int), (d,))
