"""hardpack: reproduction pipeline for jammed packings of hard particles.

Subpackages, one concern each:

- :mod:`hardpack.geometry`      packing model, d-ball volumes, periodic neighbour search, lattices
- :mod:`hardpack.distributions` particle-size distributions (Ogarko's parameterisation)
- :mod:`hardpack.io`            netCDF store with provenance, atomic writes, ensembles
- :mod:`hardpack.md`            event-driven MD with Lubachevsky-Stillinger growth
- :mod:`hardpack.jamming`       linear-programming jamming tests, rattlers, contact forces
- :mod:`hardpack.slp`           sequential linear programming (adaptive shrinking cell)
- :mod:`hardpack.eos`           equations of state, moments and equivalent mixtures
- :mod:`hardpack.freeenergy`    bounding-cell MD free energies
- :mod:`hardpack.structure`     g2(r), S(k), order metrics, channel analysis
- :mod:`hardpack.plots`         figures
"""

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

try:
    __version__ = _version("hardpack")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+unknown"

from hardpack.errors import InvalidInputError  # noqa: E402

__all__ = ["Packing", "InvalidInputError", "__version__"]


def __getattr__(name):
    """``hardpack.Packing``, imported on first use: the workflow's config checks import
    :mod:`hardpack.config` in every Snakemake process, which must not pay for numba."""
    if name == "Packing":
        from hardpack.geometry.packing import Packing

        return Packing
    raise AttributeError(f"module 'hardpack' has no attribute {name!r}")
