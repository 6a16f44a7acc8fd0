"""Fixtures shared by many test files (packings and the workflow's rules), built once per session.

- ``rsa_file``: 100 equal spheres (radius 1/2) at phi = 0.3 in a periodic cube, placed by random
  sequential addition (seed 2), saved as a packing netCDF (attribute ``seed = 2``): the start of
  the command-line and MD-limit tests.
- ``workflow_rules``: {rule name: its text} of every rule in ``workflow/rules/*.smk``.
- ``ideal_gas``: a factory ``ideal_gas(n, d, length, radii=0.01, seed=0)`` of n uniform random
  points (overlapping spheres of radii ``radii``) in a periodic cube of side ``length``.
- ``jammed_disks``: the 64-disk bidisperse packing jammed to exact contacts, read from
  ``tests/data`` (how it was made: ``test_jamming_support.make_jammed_disks``).
- ``no_slurm_controller`` (automatic): the Snakemake runs of the tests see a ``scontrol`` that
  fails at once. The SLURM executor plugin asks ``scontrol show config`` for its defaults when
  Snakemake starts, and on a host where SLURM is installed but no controller runs, that call waits
  ~9 s (10 s timeout) in each of the tests' Snakemake runs; the plugin's answer without SLURM is
  its defaults, which is what the tests expect.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

from hardpack.distributions import monodisperse
from hardpack.geometry.packing import Packing
from hardpack.initial import random_packing
from hardpack.io import save_packing


@pytest.fixture(scope="session", autouse=True)
def no_slurm_controller(tmp_path_factory):
    stub_dir = tmp_path_factory.mktemp("no-slurm")
    stub = stub_dir / "scontrol"
    stub.write_text("#!/bin/sh\necho 'scontrol: no SLURM controller in the tests' >&2\nexit 1\n")
    stub.chmod(0o755)
    saved = os.environ.get("PATH", "")
    os.environ["PATH"] = f"{stub_dir}{os.pathsep}{saved}"
    yield stub
    os.environ["PATH"] = saved


@pytest.fixture(scope="session")
def rsa_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("rsa") / "init.nc"
    save_packing(random_packing(100, 3, monodisperse(0.5), 0.3, seed=2), path, attrs={"seed": 2})
    return path


@pytest.fixture(scope="session")
def ideal_gas():
    def make(n, d, length, radii=0.01, seed=0):
        rng = np.random.default_rng(seed)
        radii = np.broadcast_to(np.asarray(radii, float), (n,))
        return Packing(rng.random((n, d)) * length, radii, np.eye(d) * length, allow_overlap=True)

    return make


@pytest.fixture(scope="session")
def jammed_disks():
    from test_jamming_support import jammed_disks as load

    return load()


@pytest.fixture(scope="session")
def workflow_rules():
    rules = {}
    for path in sorted((Path(__file__).resolve().parents[1] / "workflow" / "rules").glob("*.smk")):
        for block in re.split(r"^(?=rule )", path.read_text(), flags=re.M)[1:]:
            rules[re.match(r"rule (\w+):", block).group(1)] = block
    return rules
