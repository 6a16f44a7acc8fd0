"""Provenance attributes carried by every dataset hardpack writes.

Attributes (all netCDF-safe scalars or strings):
``hardpack_version``, ``git_commit`` (``<sha>[-dirty]`` of the source tree when it is a git
checkout, else "unknown"), ``created`` (UTC ISO 8601), ``python_version`` and the versions of
numpy, scipy, numba, xarray and netCDF4, plus ``config`` (JSON of the parameters used) and
``seed`` when given.
"""

from __future__ import annotations

import datetime as _dt
import functools
import json
import platform
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

_PACKAGES = ("numpy", "scipy", "numba", "xarray", "netCDF4")


@functools.lru_cache(maxsize=1)
def git_commit() -> str:
    """Commit of the hardpack source tree, with '-dirty' for uncommitted changes, or 'unknown'."""
    here = Path(__file__).resolve().parent
    try:
        sha = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=here, capture_output=True, text=True, timeout=10
        )
        if sha.returncode != 0:
            return "unknown"
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no", "--", "."],
            cwd=here, capture_output=True, text=True, timeout=10,
        )
        return sha.stdout.strip() + ("-dirty" if dirty.stdout.strip() else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def _version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def provenance(config=None, seed: int | None = None) -> dict:
    """Attributes describing how a result was made (see the module docstring).

    Parameters
    ----------
    config : object, optional
        The parameters used; stored as sorted JSON in ``config`` (non-JSON values via ``str``).
    seed : int, optional
        The random seed; stored as ``seed``.

    Returns
    -------
    dict
        ``hardpack_version``, ``git_commit``, ``created`` (UTC ISO 8601), ``python_version``,
        ``<package>_version`` for numpy, scipy, numba, xarray and netCDF4 ("not installed" if
        absent), and ``config`` and ``seed`` when given.
    """
    attrs = {
        "hardpack_version": _version("hardpack"),
        "git_commit": git_commit(),
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "python_version": platform.python_version(),
    }
    for name in _PACKAGES:
        attrs[f"{name}_version"] = _version(name)
    if config is not None:
        attrs["config"] = json.dumps(config, sort_keys=True, default=str)
    if seed is not None:
        attrs["seed"] = int(seed)
    return attrs
