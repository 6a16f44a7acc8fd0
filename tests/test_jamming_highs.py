"""HiGHS wrapper (hardpack.jamming.highs): a presolve 'infeasible' verdict is confirmed."""

import math
from pathlib import Path

import pytest

from hardpack.io import dataset_to_packing, load_dataset
from hardpack.jamming import verify

DATA = Path(__file__).parent / "data"


def test_slp_barlow_crystal_is_strictly_jammed_despite_presolve():
    """An N = 64 SLP packing (Torquato-Jiao Table II settings) that crystallised into a Barlow
    stacking, phi = pi / sqrt(18) to 1e-9. Its local-jamming LP 4.15 (feasible: dr = 0 is a
    solution, every gap >= 0) was declared infeasible by HiGHS's presolve at the 1e-10
    tolerances, which stopped the smoke DAG; the wrapper now confirms such verdicts without
    presolve. Close-packed stackings are strictly jammed (Donev ch. 4), with no rattlers."""
    packing = dataset_to_packing(load_dataset(DATA / "slp_barlow_n64.nc", kind="packing"))
    assert packing.phi == pytest.approx(math.pi / math.sqrt(18), abs=1e-9)
    result = verify(packing, seed=0)
    assert result.category == "strictly jammed"
    assert not result.rattler.any()
