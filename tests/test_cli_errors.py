"""What a new user hits on the command line: one-line refusals (exit 2) instead of tracebacks,
output paths checked before a run starts, checkpoints kept until the output is written, file
modes that follow the umask, and ``hardpack combine`` refusing members that do not belong
together."""

import os
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr

from hardpack.cli import main
from hardpack.distributions import monodisperse
from hardpack.initial import random_packing
from hardpack.io import load_dataset, load_packing, save_packing, write_dataset
from hardpack.md import StopCriteria, compress


def _error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err  # one line, no traceback
    return err[0]


def _init(out, *extra):
    return ["init", "--n", "20", "--d", "3", "--phi", "0.2", "--seed", "1", "--out", str(out), *extra]


def _unwritable_folder(tmp_path):
    """A folder in which no file can be created, even by root (a read-only file system)."""
    if os.geteuid() != 0:
        folder = tmp_path / "readonly"
        folder.mkdir()
        folder.chmod(0o555)
        return folder
    return "/proc"


# ---------------------------------------------------------------- tracebacks -> one-line messages
@pytest.mark.parametrize("extra, expected", [
    (["--distribution", '{"kind": "uniform_size", "omega": "4"}'],
     "hardpack init: error: distribution 'uniform_size': omega must be a number, got '4'"),
    (["--distribution", '{"kind": "discrete", "radii": [1, "2"], "fractions": [0.5, 0.5]}'],
     "hardpack init: error: distribution 'discrete': radii must be a list of numbers"),
    (["--seed", "-1"], "hardpack init: error: --seed must be an integer from 0 to 2**63 - 1, got -1"),
    (["--seed", str(2**64)], "hardpack init: error: --seed must be an integer from 0 to 2**63 - 1"),
])
def test_bad_values_end_in_one_line(tmp_path, capsys, extra, expected):
    assert main(_init(tmp_path / "x.nc", *extra)) == 2
    assert _error(capsys).startswith(expected)
    assert not (tmp_path / "x.nc").exists()


def test_output_that_is_a_folder_or_unwritable(tmp_path, capsys):
    assert main(_init(tmp_path)) == 2
    assert _error(capsys) == (f"hardpack init: error: --out {tmp_path} is a folder; give a file path "
                              f"such as {tmp_path / 'result.nc'}")
    folder = _unwritable_folder(tmp_path)
    assert main(_init(f"{folder}/x.nc")) == 2
    assert _error(capsys).startswith(f"hardpack init: error: --out {folder}/x.nc cannot be written: "
                                     f"cannot create files in folder {folder}")
    file = tmp_path / "file.nc"
    file.write_text("")
    assert main(_init(file / "x.nc")) == 2
    assert _error(capsys) == (f"hardpack init: error: --out {file / 'x.nc'} cannot be written: "
                              f"{file} is a file, not a folder")


def test_os_errors_at_write_end_in_one_line(tmp_path, capsys, monkeypatch):
    import hardpack.io

    def full_disk(*args, **kwargs):
        raise OSError(28, "No space left on device", str(tmp_path / "x.nc"))

    monkeypatch.setattr(hardpack.io, "save_packing", full_disk)
    assert main(_init(tmp_path / "x.nc")) == 2
    assert _error(capsys) == f"hardpack init: error: No space left on device: {tmp_path / 'x.nc'}"


def test_closed_stdout_ends_quietly(rsa_file):
    proc = subprocess.Popen([sys.executable, "-m", "hardpack.cli", "info", str(rsa_file)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # like `hardpack info FILE | head -0`: nothing will be read
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141
    assert err == ""


# ---------------------------------------------------------------- long runs: check first, write safely
@pytest.mark.parametrize("option", ["--out", "--timeseries", "--checkpoint"])
def test_compress_checks_outputs_before_running(tmp_path, capsys, rsa_file, option):
    paths = {"--out": tmp_path / "p.nc", "--timeseries": tmp_path / "ts.nc", "--checkpoint": tmp_path / "c.npz"}
    paths[option] = tmp_path  # a folder
    args = ["compress", "--init", str(rsa_file), "--growth-rate", "0.1", "--seed", "1",
            "--max-collisions", "5000000"] + [x for k, v in paths.items() for x in (k, str(v))]
    started = time.perf_counter()
    assert main(args) == 2
    assert time.perf_counter() - started < 10  # refused before the (minute-long) run
    assert _error(capsys).startswith(f"hardpack compress: error: {option} {tmp_path} is a folder")


def test_every_long_command_checks_its_outputs(tmp_path, capsys, rsa_file):
    folder = str(tmp_path)
    commands = [
        ["eos", "--init", str(rsa_file), "--out", folder, "--seed", "1", "--collisions", "10000000"],
        ["poly-jam", "--distribution", '{"kind": "monodisperse"}', "--seed", "1", "--systems", "poly",
         "--out", folder],
        ["slp", "--init", str(rsa_file), "--out", folder],
        ["verify", str(rsa_file), "--out", folder, "--method", "sequential"],
        ["bcmd", str(rsa_file), "--out", folder, "--dmu-max", "1"],
        ["structure", str(rsa_file), "--out", folder],
        ["poly-fluid", "--distribution", '{"kind": "monodisperse"}', "--phi", "0.3", "--seed", "1",
         "--out", folder],
    ]
    for args in commands:
        assert main(args) == 2, args
        assert _error(capsys) == (f"hardpack {args[0]}: error: --out {folder} is a folder; give a file "
                                  f"path such as {tmp_path / 'result.nc'}")


def test_checkpoint_is_kept_until_the_output_is_written(tmp_path, capsys, rsa_file, monkeypatch):
    import sys

    writer = sys.modules["hardpack.md.compress"]  # the module (hardpack.md.compress is the function)
    reference = compress(load_packing(rsa_file), 0.05, 1, stop=StopCriteria(max_pressure=1e8)).packing
    out, ckpt = tmp_path / "out.nc", tmp_path / "run.ckpt.npz"
    args = ["compress", "--init", str(rsa_file), "--out", str(out), "--growth-rate", "0.05", "--seed", "1",
            "--max-pressure", "1e8", "--checkpoint", str(ckpt), "--checkpoint-interval", "0"]
    saved = writer.write_dataset

    def fails(*a, **k):
        raise OSError(28, "No space left on device", str(out))

    monkeypatch.setattr(writer, "write_dataset", fails)
    assert main(args) == 2
    assert "No space left on device" in _error(capsys)
    assert ckpt.exists() and not out.exists()
    monkeypatch.setattr(writer, "write_dataset", saved)
    assert main(args) == 0
    final = load_packing(out)
    np.testing.assert_array_equal(final.positions, reference.positions)
    np.testing.assert_array_equal(final.radii, reference.radii)
    assert not ckpt.exists()


# ---------------------------------------------------------------- file modes
@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_outputs_follow_the_umask(tmp_path, umask, mode):
    old = os.umask(umask)
    try:
        path = save_packing(random_packing(10, 2, monodisperse(), 0.2, seed=1), tmp_path / "p.nc")
    finally:
        os.umask(old)
    assert path.stat().st_mode & 0o777 == mode


def test_rewrite_keeps_the_mode_of_the_replaced_file(tmp_path):
    path = tmp_path / "p.nc"
    packing = random_packing(10, 2, monodisperse(), 0.2, seed=1)
    save_packing(packing, path)
    path.chmod(0o640)
    save_packing(packing, path)
    assert path.stat().st_mode & 0o777 == 0o640


# ---------------------------------------------------------------- combine
@pytest.fixture
def members(tmp_path):
    paths = []
    for seed, d in ((1, 3), (2, 3), (3, 2)):
        path = tmp_path / f"d{d}_seed{seed}.nc"
        save_packing(random_packing(20, d, monodisperse(), 0.2, seed=seed), path, attrs={"seed": seed})
        paths.append(str(path))
    return paths


def test_combine_refuses_a_file_given_twice(tmp_path, capsys, members):
    a = members[0]
    assert main(["combine", a, members[1], a, "--out", str(tmp_path / "s.nc")]) == 2
    assert _error(capsys) == f"hardpack combine: error: {a} is given twice ({a} and {a}); give each file once"


def test_combine_refuses_identical_index_values(tmp_path, capsys, members):
    copy = tmp_path / "copy.nc"
    copy.write_bytes(open(members[0], "rb").read())
    assert main(["combine", members[0], str(copy), "--out", str(tmp_path / "s.nc")]) == 2
    assert _error(capsys).startswith(f"hardpack combine: error: {members[0]} and {copy} have the same "
                                     "index values (seed = 1)")


def test_combine_refuses_mixed_dimensions_unless_indexed(tmp_path, capsys, members):
    assert main(["combine", *members, "--out", str(tmp_path / "s.nc")]) == 2
    assert _error(capsys) == (f"hardpack combine: error: the files are of different dimensions (d = 3: "
                              f"{members[0]}, {members[1]}; d = 2: {members[2]}); combine one dimension "
                              "at a time, or add d to --index to tabulate them together")
    assert main(["combine", *members, "--index", "d", "seed", "--out", str(tmp_path / "s.nc")]) == 0
    assert list(load_dataset(tmp_path / "s.nc")["d"].values) == [3, 3, 2]


def test_combine_refuses_other_kinds_among_packings(tmp_path, capsys, members):
    verdict = tmp_path / "verdict.nc"
    write_dataset(xr.Dataset({"rattler": ("particle", np.zeros(20, bool))},
                             attrs={"hardpack_kind": "jamming", "seed": 7, "d": 3}), verdict)
    assert main(["combine", members[0], str(verdict), "--out", str(tmp_path / "s.nc")]) == 2
    assert _error(capsys) == (f"hardpack combine: error: the files hold different kinds of results "
                              f"(packing: {members[0]}; jamming: {verdict}); combine files of one kind "
                              "only (e.g. only packings)")
    foreign = tmp_path / "foreign.nc"
    xr.Dataset({"x": ("i", [1.0])}, attrs={"seed": 9}).to_netcdf(foreign)
    assert main(["combine", members[0], str(foreign), "--out", str(tmp_path / "s.nc")]) == 2
    assert _error(capsys) == (f"hardpack combine: error: {foreign}: not a hardpack result "
                              "(no hardpack_kind attribute)")


# ---------------------------------------------------------------- overlapping packings
@pytest.fixture
def overlapping(tmp_path):
    from hardpack.geometry.packing import Packing

    path = tmp_path / "overlap.nc"
    p = Packing([[0.0, 0.0], [0.8, 0.0], [2.0, 2.0]], [0.5, 0.5, 0.5], 4 * np.eye(2), allow_overlap=True)
    save_packing(p, path)
    return path


def test_overlapping_packings_are_refused_with_an_actionable_hint(tmp_path, capsys, overlapping):
    for command in (["structure", str(overlapping), "--out", str(tmp_path / "s.nc")],
                    ["compress", "--init", str(overlapping), "--out", str(tmp_path / "c.nc"),
                     "--growth-rate", "0.1", "--seed", "1"]):
        assert main(command) == 2
        line = _error(capsys)
        assert line.startswith(f"hardpack {command[0]}: error: {overlapping} holds an invalid packing: "
                               "particles overlap beyond the tolerance")
        assert "regenerate the packing or shrink the radii (`hardpack info FILE` lists the overlaps)" in line
    assert not (tmp_path / "s.nc").exists()


def test_info_shows_overlaps_and_says_it_is_a_diagnosis(capsys, overlapping):
    assert main(["info", str(overlapping)]) == 0
    out = capsys.readouterr().out
    assert "overlaps: " in out and "shown for diagnosis: every other command refuses" in out



# ---------------------------------------------------------------- signals outside a polling run
def test_a_signal_during_any_command_ends_in_one_line(tmp_path, capsys, rsa_file, monkeypatch):
    """SIGTERM while a command without its own polling runs (here: the sequential jamming test,
    which checkpoints after every loading sequence) ends in one line with status 143, says where
    the checkpoint is, and leaves the caller's signal handlers as they were."""
    import signal

    import hardpack.jamming.cli

    def killed(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # the handler raises before this ends
        raise AssertionError("SIGTERM was not handled")

    monkeypatch.setattr(hardpack.jamming.cli, "verify", killed)
    before = signal.getsignal(signal.SIGTERM)
    ckpt = tmp_path / "v.ckpt"
    assert main(["verify", str(rsa_file), "--out", str(tmp_path / "v.nc"), "--method", "sequential",
                 "--checkpoint", str(ckpt)]) == 143
    assert _error(capsys) == (f"hardpack verify: interrupted: stopped by SIGTERM; a checkpoint written "
                              f"before is kept in {ckpt}: start the same command again to resume from it")
    assert signal.getsignal(signal.SIGTERM) is before
