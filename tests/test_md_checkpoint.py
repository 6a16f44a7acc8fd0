"""Checkpoint/resume through the command line: a run killed with SIGKILL and started again with
the same arguments resumes and ends with a bit-identical packing; plus the ``eos`` subcommand."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from hardpack.distributions import monodisperse
from hardpack.initial import random_packing
from hardpack.io import load_dataset, load_packing, save_packing
from hardpack.md import StopCriteria, compress

# a run of ~1 s of MD on a fast host (0.3 s at growth rate 0.05 left too little time after the resume
# for the signal to reach the run proper)
ARGS = ["--growth-rate", "0.02", "--seed", "1", "--max-pressure", "1e10"]


def _cli(*args):
    return [sys.executable, "-m", "hardpack.md.cli", *args]


@pytest.fixture(scope="module")
def init_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("md") / "init.nc"
    save_packing(random_packing(500, 3, monodisperse(0.5), 0.3, seed=2), path)
    return path


def _killed_after_first_checkpoint(base, ckpt, progress) -> int:
    """Run ``base`` with a checkpoint after every window, SIGKILL it once ``progress(ckpt)`` >= 1
    (a checkpoint of the run proper was written); return that progress."""
    first = subprocess.Popen([*base, "--checkpoint-interval", "0"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while progress(ckpt) < 1:
        assert first.poll() is None and time.time() < deadline
        time.sleep(0.01)
    os.kill(first.pid, signal.SIGKILL)
    first.wait()
    return progress(ckpt)


def _resumed_and_signalled(base, ckpt, sig) -> str:
    """Start ``base`` again (no timed checkpoints), send ``sig`` once it has resumed from
    ``ckpt``, check the exit status 128 + sig and return its standard error."""
    run = subprocess.Popen([*base, "--checkpoint-interval", "1e9"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True)
    for line in run.stderr:  # logged inside the deferred section: the signal now reaches the run proper
        if "resumed from" in line and str(ckpt) + " " in line:
            break
    assert run.poll() is None, "the run ended before the signal"
    os.kill(run.pid, sig)
    err = run.stderr.read()
    assert run.wait(timeout=120) == 128 + sig
    return err


def _windows(path):
    try:
        with np.load(path) as data:
            return int(data["windows"])
    except (OSError, KeyError, ValueError):
        return -1


def test_sigkill_and_resume_is_bit_identical(tmp_path, init_file):
    reference = compress(load_packing(init_file), 0.02, 1, stop=StopCriteria(max_pressure=1e10)).packing
    out, ckpt = tmp_path / "out.nc", tmp_path / "run.ckpt.npz"
    cmd = _cli("compress", "--init", str(init_file), "--out", str(out), *ARGS,
               "--checkpoint", str(ckpt), "--checkpoint-interval", "0")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    deadline = time.time() + 120
    while _windows(ckpt) < 20:  # let it write a few checkpoints, then kill it hard
        assert proc.poll() is None, "the run ended before it could be killed"
        assert time.time() < deadline
        time.sleep(0.01)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists() and ckpt.exists()

    again = subprocess.run(cmd, capture_output=True, text=True, timeout=300, check=False)
    assert again.returncode == 0, again.stderr
    assert "resumed from" in again.stderr
    final = load_packing(out)
    np.testing.assert_array_equal(final.positions, reference.positions)
    np.testing.assert_array_equal(final.radii, reference.radii)
    assert not ckpt.exists()  # removed after a successful run


def test_checkpoint_of_another_run_is_refused(tmp_path, init_file):
    ckpt = tmp_path / "c.npz"
    cmd = _cli("compress", "--init", str(init_file), "--out", str(tmp_path / "o.nc"), "--growth-rate",
               "0.05", "--seed", "1", "--max-collisions", "20000", "--checkpoint", str(ckpt), "--window", "1")
    _killed_after_first_checkpoint(cmd, ckpt, _windows)
    other = subprocess.run(
        _cli("compress", "--init", str(init_file), "--out", str(tmp_path / "o.nc"), "--growth-rate",
             "0.05", "--seed", "2", "--max-collisions", "20000", "--checkpoint", str(ckpt),
             "--window", "1"), capture_output=True, text=True, check=False)
    assert other.returncode == 2
    assert "different run" in other.stderr


def test_cli_writes_packing_timeseries_and_eos(tmp_path, init_file):
    out, ts, eos = tmp_path / "p.nc", tmp_path / "ts.nc", tmp_path / "eos.nc"
    run = subprocess.run(_cli("compress", "--init", str(init_file), "--out", str(out), "--timeseries",
                              str(ts), "--growth-rate", "0.1", "--seed", "3", "--max-pressure", "none",
                              "--target-phi", "0.35"), capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    attrs = load_dataset(out).attrs
    assert attrs["stop_reason"] == "target_phi" and abs(attrs["phi"] - 0.35) < 1e-12
    assert load_dataset(ts).sizes["window"] >= 1
    run = subprocess.run(_cli("eos", "--init", str(out), "--out", str(eos), "--seed", "4",
                              "--collisions", "50000", "--blocks", "10"), capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    ds = load_dataset(eos)
    # Carnahan-Starling at phi = 0.35 is 5.2057; 5e4 collisions right after a fast compression
    # give a ~1 % uncertainty, hence 3 %
    assert ds.attrs["Z"] == pytest.approx(1.429625 / 0.65**3, rel=0.03)
    assert ds.sizes["block"] == 10


def test_damaged_checkpoint_is_refused(tmp_path, init_file):
    from hardpack.errors import InvalidInputError

    ckpt = tmp_path / "bad.npz"
    ckpt.write_bytes(b"not a checkpoint")
    with pytest.raises(InvalidInputError, match="cannot be read"):
        compress(load_packing(init_file), 0.05, 1, checkpoint=ckpt)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_writes_a_checkpoint_and_resume_is_bit_identical(tmp_path, init_file, sig):
    reference = compress(load_packing(init_file), 0.02, 1, stop=StopCriteria(max_pressure=1e10)).packing
    out, ckpt = tmp_path / "out.nc", tmp_path / "run.ckpt.npz"
    base = _cli("compress", "--init", str(init_file), "--out", str(out), *ARGS, "--checkpoint", str(ckpt))
    early = _killed_after_first_checkpoint(base, ckpt, _windows)
    # the second run writes no timed checkpoint: only the signal makes it write one
    err = _resumed_and_signalled(base, ckpt, sig)
    assert not out.exists() and _windows(ckpt) > early
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"hardpack compress: interrupted: stopped by {signal.Signals(sig).name} at phi = ")
    assert last.endswith(f"checkpoint written to {ckpt}: start the same run again (same arguments and "
                         "checkpoint) to resume")

    again = subprocess.run([*base, "--checkpoint-interval", "1e9"], capture_output=True, text=True,
                           timeout=300, check=False)
    assert again.returncode == 0, again.stderr
    assert "resumed from" in again.stderr
    final = load_packing(out)
    np.testing.assert_array_equal(final.positions, reference.positions)
    np.testing.assert_array_equal(final.radii, reference.radii)
    assert not ckpt.exists()


def _collisions(path):
    try:
        with np.load(path) as data:
            return int(data["collisions"])
    except (OSError, KeyError, ValueError):
        return -1


@pytest.mark.slow
def test_eos_sigterm_and_resume_is_bit_identical(tmp_path, init_file):
    args = ["eos", "--init", str(init_file), "--phi", "0.4", "--seed", "5", "--collisions", "1500000",
            "--blocks", "10"]
    reference = tmp_path / "reference.nc"
    run = subprocess.run(_cli(*args, "--out", str(reference)), capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    out, ckpt = tmp_path / "eos.nc", tmp_path / "eos.ckpt"
    base = _cli(*args, "--out", str(out), "--checkpoint", str(ckpt))
    early = _killed_after_first_checkpoint(base, ckpt, _collisions)  # the equilibrium run's state
    err = _resumed_and_signalled(base, ckpt, signal.SIGTERM)
    assert _collisions(ckpt) > early and not out.exists()
    assert err.strip().splitlines()[-1].startswith("hardpack eos: interrupted: stopped by SIGTERM at ")

    again = subprocess.run([*base, "--checkpoint-interval", "1e9"], capture_output=True, text=True,
                           timeout=300, check=False)
    assert again.returncode == 0, again.stderr
    np.testing.assert_array_equal(load_dataset(out)["Z_block"].values,
                                  load_dataset(reference)["Z_block"].values)
    assert not ckpt.exists() and not (tmp_path / "eos.ckpt.prep").exists()
