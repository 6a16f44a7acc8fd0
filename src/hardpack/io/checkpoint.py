"""Atomic checkpoints of long runs (MD compressions, SLP densifications, sequential jamming tests).

A checkpoint is an ``.npz`` file with the complete state of a run (for MD:
:meth:`hardpack.md.simulation.Simulation.state`, written at synchronisation points; for SLP:
:func:`hardpack.slp.driver.run_slp`'s packing, trust region and history; for the sequential
jamming tests: the random generator as the test found it and the statistics after each
loading sequence, :func:`hardpack.jamming.verify.verify`) plus a fingerprint of
the run's defining inputs (for MD: start packing, growth rate, seed, window size, overlap
tolerance, final growth stage, contact-force windows).
It is written by :func:`hardpack.io.atomic.atomic_path` (a temporary file in the destination folder,
flushed and renamed over the old one), so a run killed at any moment (even with SIGKILL) leaves a complete
checkpoint. Restarting with the same arguments loads it and continues. MD checkpoints are taken only
at synchronisation points after which the uninterrupted run also rebuilds its schedule and its
neighbour lists from scratch (:attr:`Simulation.checkpoint_ready`), so the continued run is
bit-identical to an uninterrupted one.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from pathlib import Path

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.io.atomic import atomic_path

FORMAT = 2


def fingerprint(packing, **params) -> str:
    """SHA-256 over the start packing's arrays and the run parameters that shape the trajectory.

    Parameters
    ----------
    packing : Packing
        The start packing.
    **params
        The run parameters (JSON-serialisable, others by ``str``).

    Returns
    -------
    str
        Hexadecimal digest.
    """
    h = hashlib.sha256()
    for arr in (packing.positions, packing.radii, packing.lattice):
        h.update(np.ascontiguousarray(arr, dtype=float).tobytes())
    h.update(json.dumps({"format": FORMAT, **params}, sort_keys=True, default=str).encode())
    return h.hexdigest()


def save(path, fp: str, state: dict) -> None:
    """Atomically write ``state`` (arrays and scalars) with fingerprint ``fp`` to ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        The checkpoint file.
    fp : str
        Fingerprint of the run (:func:`fingerprint`).
    state : dict of str to array_like
        The run state.
    """
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, fingerprint=np.array(fp), format=np.array(FORMAT), **state)


def load(path, fp: str) -> dict | None:
    """The saved state, or None if ``path`` does not exist. A checkpoint of a different run (other
    start packing or parameters) is refused rather than silently continued.

    Parameters
    ----------
    path : str or os.PathLike
        The checkpoint file.
    fp : str
        Fingerprint of the run (:func:`fingerprint`).

    Returns
    -------
    dict of str to numpy.ndarray or None
        The state.

    Raises
    ------
    InvalidInputError
        For an unreadable checkpoint or one of a different run.
    """
    path = Path(path)
    if not path.exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            state = {k: data[k] for k in data.files}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:  # damaged zip / npy contents
        raise InvalidInputError(f"checkpoint {path} cannot be read ({type(exc).__name__}: {exc}); "
                                "delete it to start afresh") from None
    if int(state.pop("format", -1)) != FORMAT or str(state.pop("fingerprint", "")) != fp:
        raise InvalidInputError(
            f"checkpoint {path} belongs to a different run (other start packing or run parameters, "
            "e.g. growth rates, seed, window size, SLP bounds); delete it or choose another checkpoint path"
        )
    return {k: (v.item() if v.ndim == 0 else v) for k, v in state.items()}


def remove(path) -> None:
    """Delete a checkpoint file if it exists.

    Parameters
    ----------
    path : str or os.PathLike
        The checkpoint file.
    """
    Path(path).unlink(missing_ok=True)
