"""One compiled ellipsoid event loop for every boundary.

The ellipsoid kernel takes its boundary (periodic cell, flat hard walls, spherical container) as a
run-time code (:data:`hardpack.md._ellipsoid_kernel.PERIODIC_CODE` and its siblings), so that one
compilation of its event loop (~80 s of numba/LLVM time) serves all three; a compile-time mode
would triple that in every fresh environment (CI, a new cluster node). Numba also compiles a
separate version of a function for each Literal-int argument it is called with from compiled
code; the kernel passes ``np.int64`` values to avoid it. This test fails if either comes back.
"""

from __future__ import annotations

from hardpack.initial import random_ellipsoid_packing
from hardpack.md import StopCriteria
from hardpack.md import _ellipsoid_kernel as ek
from hardpack.md.ellipsoid import compress_ellipsoids


def _signatures(dispatcher) -> set[str]:
    """Every compiled signature of a kernel function: those in memory and those in its numba cache
    index (a function compiled inside another one that was loaded from the cache is not in memory;
    the index is that of the current source, numba drops it when the source changes)."""
    index = getattr(dispatcher._cache, "_cache_file", None)  # none when numba's cache is off
    cached = index._load_index() if index is not None else {}
    return {str(tuple(sig)) for sig in dispatcher.signatures} | {str(key[0]) for key in cached}


def test_one_event_loop_serves_periodic_cells_walls_and_containers():
    semiaxes = [1.3, 1.0, 0.8]
    starts = [
        random_ellipsoid_packing(6, semiaxes, 0.1, seed=1),
        random_ellipsoid_packing(6, semiaxes, 0.1, seed=1, boundary="hard_walls", wall_axes=[2]),
        random_ellipsoid_packing(6, semiaxes, 0.05, seed=1, boundary="spherical_container"),
    ]
    for start in starts:
        run = compress_ellipsoids(start, 0.1, 1, StopCriteria(max_pressure=None, target_phi=0.15))
        assert abs(run.packing.phi - 0.15) < 1e-9
    assert len(_signatures(ek.run_events)) == 1
    assert len(_signatures(ek._run)) == 1
    for dispatcher in (ek._predict_shared, ek.wall_predict, ek.wall_gap):
        assert not any("Literal" in sig for sig in _signatures(dispatcher)), _signatures(dispatcher)
