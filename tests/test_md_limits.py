"""Compressions that cannot do what was asked: a target phi above the jamming density reached
(refused instead of running forever), an end state far from jammed (flagged), and hard rods in
d = 1, whose equilibrium pressure is Tonks' exact Z = 1 / (1 - phi)."""

import logging
import subprocess
import sys

import pytest

from hardpack.cli import main
from hardpack.distributions import monodisperse
from hardpack.initial import random_packing
from hardpack.io import load_dataset, save_packing
from hardpack.md import StopCriteria, compress


@pytest.mark.parametrize("command", [
    ["compress", "--target-phi", "0.9", "--max-pressure", "none", "--growth-rate", "0.1"],
    ["eos", "--phi", "0.9", "--collisions", "10000"],
])
def test_target_above_jamming_is_refused(tmp_path, rsa_file, command):
    # without the check both runs grow towards phi = 0.9 forever (the timeout fails the test)
    run = subprocess.run([sys.executable, "-m", "hardpack.cli", command[0], "--init", str(rsa_file), "--out",
                          str(tmp_path / "out.nc"), "--seed", "1", *command[1:]],
                         capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 2
    line = run.stderr.strip().splitlines()[-1]
    assert line.startswith(f"hardpack {command[0]}: error: target phi 0.9 is above the jamming density "
                           "reached: at growth rate 0.1 the packing jammed at phi = 0.6")
    assert "Choose a target phi below it, or compress more slowly" in line
    phi_j = float(line.split("jammed at phi = ")[1].split()[0])
    assert 0.55 < phi_j < 0.66  # LS at Gamma = 0.1 in 3D
    assert not (tmp_path / "out.nc").exists()


def test_target_below_jamming_is_still_reached():
    packing = random_packing(100, 3, monodisperse(0.5), 0.3, seed=2)
    res = compress(packing, 0.1, 1, stop=StopCriteria(max_pressure=None, target_phi=0.55))
    assert res.stats["stop_reason"] == "target_phi" and res.packing.phi == pytest.approx(0.55, abs=1e-12)
    assert res.stats["Z"] < 1e9


def test_end_state_far_from_jammed_is_flagged(tmp_path, rsa_file, caplog):
    out = tmp_path / "fast.nc"
    with caplog.at_level(logging.WARNING, logger="hardpack.md"):
        assert main(["compress", "--init", str(rsa_file), "--out", str(out), "--growth-rate", "1e6",
                     "--seed", "1"]) == 0
    attrs = load_dataset(out).attrs
    assert attrs["stop_reason"] == "max_pressure" and attrs["phi"] < 0.5
    assert attrs["jamming_check"] == "far_from_jammed" and attrs["backbone_volume_fraction"] < 0.01
    assert "the end state is far from jammed" in caplog.text and "too fast" in caplog.text


def test_jammed_end_state_passes(rsa_file):
    from hardpack.io import load_packing

    res = compress(load_packing(rsa_file), 0.02, 1)
    assert res.stats["jamming_check"] == "passed"
    assert res.stats["backbone_volume_fraction"] > 0.9  # a few percent rattlers


def test_rods_in_one_dimension_are_never_jammed_below_phi_one(caplog):
    rods = random_packing(100, 1, monodisperse(), 0.3, seed=1)
    with caplog.at_level(logging.WARNING, logger="hardpack.md"):
        res = compress(rods, 0.1, 1)
    assert res.stats["phi"] < 1 and res.stats["jamming_check"] == "far_from_jammed"
    assert "hard rods (d = 1) jam only at phi = 1" in caplog.text


@pytest.mark.parametrize("phi", [0.5, 0.8])
def test_hard_rods_obey_tonks(tmp_path, phi):
    """Tonks (1936): hard rods on a line have Z = pL/(NkT) = 1 / (1 - phi) exactly; with equal
    masses the dynamics only exchanges velocities, so the Maxwell-Boltzmann start stays exact."""
    init, out = tmp_path / "rods.nc", tmp_path / "eos.nc"
    save_packing(random_packing(500, 1, monodisperse(), 0.3, seed=2), init)
    assert main(["eos", "--init", str(init), "--out", str(out), "--phi", str(phi), "--seed", "3",
                 "--collisions", "400000", "--blocks", "20"]) == 0
    a = load_dataset(out).attrs
    assert a["phi"] == pytest.approx(phi, abs=1e-12)
    assert abs(a["Z"] - 1 / (1 - phi)) < 3 * a["Z_err"]


def test_rods_jam_at_phi_one_where_slp_takes_them():
    """The honest 1D end state: sequential LP (exact steps) packs polydisperse rods to phi = 1 up to
    its stopping tolerance, and the jamming test finds every rod in the backbone, isostatic
    (z = 2d = 2), strictly jammed; the LS end state of the test above is not jammed."""
    from hardpack.distributions import uniform_size
    from hardpack.jamming.verify import verify
    from hardpack.slp import Bounds, run_slp

    rods = run_slp(random_packing(30, 1, uniform_size(2), 0.3, seed=3), 1.5, Bounds(0.1, 0.1, 0.5)).packing
    assert rods.phi > 1 - 1e-8
    verdict = verify(rods)
    assert verdict.summary().startswith("verdict: strictly jammed")
    assert not verdict.rattler.any()
    ls = compress(random_packing(100, 1, monodisperse(), 0.3, seed=1), 0.1, 1).packing
    assert verify(ls).summary().startswith("verdict: not jammed")


def test_eos_records_its_equilibration_and_can_start_measuring_at_once(tmp_path):
    """``--equilibration 0`` measures from the first collision (a glass's relaxation, Donev 2006,
    Fig. 13.7); the default discards a quarter of --collisions first. Both are recorded."""
    init = tmp_path / "rods.nc"
    save_packing(random_packing(200, 1, monodisperse(), 0.3, seed=2), init)
    for extra, expected in (([], 10000), (["--equilibration", "0"], 0)):
        out = tmp_path / f"eos{expected}.nc"
        assert main(["eos", "--init", str(init), "--out", str(out), "--seed", "3", "--collisions", "40000",
                     "--blocks", "4", *extra]) == 0
        a = load_dataset(out).attrs
        assert a["equilibration"] == expected and a["collisions"] == 40000
