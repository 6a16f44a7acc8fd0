"""The hardpack command line: init, info, combine, and its error messages."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from hardpack.cli import main
from hardpack.io import load_dataset, load_packing

ROOT = Path(__file__).resolve().parents[1]


def test_init_info_combine(tmp_path, capsys):
    spec = json.dumps({"kind": "uniform_size", "omega": 2})
    paths = []
    for seed in (1, 2):
        out = tmp_path / f"seed{seed}.nc"
        assert main(["init", "--n", "100", "--d", "3", "--phi", "0.2", "--distribution", spec,
                     "--seed", str(seed), "--out", str(out), "--attr", "ensemble=us2"]) == 0
        paths.append(str(out))
    p = load_packing(paths[0])
    assert p.n_particles == 100 and abs(p.phi - 0.2) < 1e-12
    attrs = load_dataset(paths[0]).attrs
    assert attrs["ensemble"] == "us2" and attrs["seed"] == 1 and attrs["distribution"] == "uniform_size"

    assert main(["info", paths[0]]) == 0
    text = capsys.readouterr().out
    assert "N = 100, d = 3, phi = 0.2" in text
    assert "radii: min" in text and "git_commit" in text and "numba_version" in text

    summary = tmp_path / "summary.nc"
    assert main(["combine", *paths, "--index", "seed", "--variable", "init_phi", "--out", str(summary)]) == 0
    ds = load_dataset(summary, kind="ensemble")
    assert list(ds["seed"].values) == [1, 2] and np.allclose(ds["init_phi"], 0.2)


def test_errors_are_reported_not_raised(tmp_path, capsys):
    assert main(["info", str(tmp_path / "nope.nc")]) == 2
    assert "nope.nc: no such file" in capsys.readouterr().err
    assert main(["init", "--n", "10", "--d", "3", "--phi", "0.2", "--distribution",
                 '{"kind": "uniform_size"}', "--seed", "1", "--out", str(tmp_path / "x.nc")]) == 2
    assert "needs key(s) ['omega']" in capsys.readouterr().err


def test_lattice_command_writes_a_crystal(tmp_path):
    out = tmp_path / "fcc.nc"
    assert main(["lattice", "--name", "fcc", "--reps", "3", "--out", str(out)]) == 0
    p = load_packing(out)
    assert p.n_particles == 108 and abs(p.phi - np.pi / np.sqrt(18)) < 1e-12
    assert main(["lattice", "--name", "fcx", "--out", str(out)]) == 2


def test_lattice_command_refuses_bad_repetitions(tmp_path, capsys):
    """A wrong number of repetitions crashed with numpy's broadcast error; non-integers stop in
    argparse; zero is refused. Nothing is written."""
    out = tmp_path / "fcc.nc"
    assert main(["lattice", "--name", "fcc", "--reps", "2", "2", "--out", str(out)]) == 2
    assert "reps must be one repetition count or 3 of them" in capsys.readouterr().err
    assert main(["lattice", "--name", "fcc", "--reps", "0", "--out", str(out)]) == 2
    assert "positive whole numbers" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["lattice", "--name", "fcc", "--reps", "1.5", "--out", str(out)])
    assert "invalid int value: '1.5'" in capsys.readouterr().err
    assert not out.exists()


def test_init_ellipses_scale_the_semiaxes_by_the_size_distribution(tmp_path):
    """Binary ellipses (Donev 2006, Sec. 5.2): one third 1.4 times larger, shape 1 : 1.5."""
    out = tmp_path / "e.nc"
    spec = json.dumps({"kind": "bidisperse", "size_ratio": 1.4, "large_fraction": 1 / 3})
    assert main(["init", "--n", "60", "--d", "2", "--phi", "0.3", "--distribution", spec,
                 "--semiaxes", "1", "1.5", "--seed", "3", "--out", str(out)]) == 0
    p = load_packing(out)
    assert p.shape.kind == "ellipsoid" and p.phi == pytest.approx(0.3)
    assert sorted(set(np.round(p.shape.semiaxes[:, 0], 12))) == [1.0, 1.4]
    assert np.allclose(p.shape.semiaxes[:, 1] / p.shape.semiaxes[:, 0], 1.5)
    assert (p.shape.semiaxes[:, 0] == 1.4).sum() == 20
    assert load_dataset(out).attrs["semiaxes"].tolist() == [1.0, 1.5]


def test_init_refuses_semiaxes_of_the_wrong_dimension(tmp_path, capsys):
    assert main(["init", "--n", "5", "--d", "3", "--phi", "0.1", "--semiaxes", "1", "2",
                 "--seed", "1", "--out", str(tmp_path / "e.nc")]) != 0
    assert "--semiaxes needs d = 3 numbers" in capsys.readouterr().err


@pytest.mark.parametrize("extra, boundary", [
    (["--boundary", "spherical_container"], "spherical_container"),
    (["--boundary", "hard_walls"], "hard_walls"),
    (["--boundary", "hard_walls", "--wall-axes", "2"], "hard_walls"),
])
def test_init_in_a_container_and_compress_it_to_jamming(tmp_path, extra, boundary):
    """Donev 2006, Sec. 7.3.1.2: spheres grown to jamming inside hard walls or a spherical container."""
    start, out = tmp_path / "start.nc", tmp_path / "jammed.nc"
    assert main(["init", "--n", "30", "--d", "3", "--phi", "0.2", "--seed", "2", "--out", str(start), *extra]) == 0
    p = load_packing(start)
    assert p.boundary.kind == boundary and p.phi == pytest.approx(0.2)
    if "--wall-axes" in extra:
        assert p.boundary.axes == (2,)
    assert json.loads(load_dataset(start).attrs["config"])["boundary"] == boundary
    assert main(["compress", "--init", str(start), "--out", str(out), "--timeseries", str(tmp_path / "ts.nc"),
                 "--growth-rate", "0.05", "--max-pressure", "1e6", "--seed", "1"]) == 0
    jammed = load_packing(out)
    assert str(jammed.boundary) == str(p.boundary) and jammed.phi > 0.45
    assert jammed.containment_report().n_outside == 0


@pytest.mark.parametrize("extra, message", [
    (["--wall-axes", "1"], "--wall-axes is for --boundary hard_walls only"),
    (["--boundary", "hard_walls", "--wall-axes", "3"], "hard-wall axis 3 does not exist in 3 dimensions"),
    (["--boundary", "hard_walls", "--semiaxes", "1", "1", "2", "--wall-axes", "3"],
     "hard-wall axis 3 does not exist in 3 dimensions"),
    (["--semiaxes", "1", "1", "2", "--wall-axes", "1"], "--wall-axes is for --boundary hard_walls only"),
])
def test_init_refuses_bad_boundaries(tmp_path, capsys, extra, message):
    out = tmp_path / "x.nc"
    assert main(["init", "--n", "20", "--d", "3", "--phi", "0.2", "--seed", "1", "--out", str(out), *extra]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_the_subcommand_table_names_every_registered_command_and_only_those():
    """`SUBCOMMANDS` (which module registers each command) must match what the modules register:
    a missing entry would make the command load every module, a wrong one would lose it."""
    import argparse

    from hardpack import cli

    registered = {}
    for module_name in cli.SUBCOMMAND_MODULES:
        sub = argparse.ArgumentParser().add_subparsers()
        __import__(module_name, fromlist=["register"]).register(sub)
        registered.update(dict.fromkeys(sub.choices, module_name))
    assert registered == cli.SUBCOMMANDS
    full = cli.build_parser()._subparsers._group_actions[0].choices
    assert set(full) == set(cli.CORE_SUBCOMMANDS) | set(cli.SUBCOMMANDS)
    for command in full:
        assert command in cli.build_parser(command)._subparsers._group_actions[0].choices


def test_a_command_imports_only_its_own_module():
    """A job's start-up: `hardpack compress` must not import the validation, glass or free-energy
    command modules (they cost seconds of imports per job of the DAG)."""
    code = ("import sys; from hardpack.cli import build_parser; build_parser('compress'); "
            "print(sorted(m for m in sys.modules if m.endswith('.cli')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert eval(out) == ["hardpack.cli", "hardpack.md.cli"]


def test_reading_datasets_does_not_import_numba(tmp_path):
    """`hardpack combine` and most figure scripts only read datasets: the neighbour layer (numba) is
    imported on first use (an overlap check, a pair search), not by the packing model and the store
    (0.45 s of each such job's start-up)."""
    from hardpack.geometry import Packing
    from hardpack.io import save_packing

    path = tmp_path / "p.nc"
    save_packing(Packing(np.array([[0.5, 0.5]]), radii=np.array([0.5]), lattice=2.0 * np.eye(2)), path)
    code = (f"import sys; from hardpack.io import load_dataset; import hardpack.cli, hardpack.plots.style; "
            f"load_dataset({str(path)!r}); print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
    code = "import sys; from hardpack.geometry import pairs_within; print(callable(pairs_within), 'numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["True", "True"]


def test_the_console_script_tunes_the_collector_and_main_leaves_it_alone(tmp_path):
    """A job process collects its young generation every GC_THRESHOLD allocations and freezes its
    objects at exit (hardpack.process.job_process, run by hardpack.cli.console_main); main(),
    which tests call in their own process, changes neither. The installed `hardpack` script is
    console_main."""
    import gc
    import tomllib

    from hardpack.process import GC_THRESHOLD

    before = gc.get_threshold()
    assert main(["-q", "init", "--n", "4", "--d", "2", "--phi", "0.1", "--seed", "1", "--out", str(tmp_path / "a.nc")]) == 0
    assert gc.get_threshold() == before and gc.get_freeze_count() == 0
    code = ("import atexit, gc, sys; from hardpack.cli import console_main; "
            "atexit.register(lambda: print(gc.get_threshold()[0], gc.get_freeze_count() > 0)); "
            f"sys.argv = ['hardpack', '-q', 'init', '--n', '4', '--d', '2', '--phi', '0.1', '--seed', '1', '--out', "
            f"{str(tmp_path / 'b.nc')!r}]; console_main()")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == [str(GC_THRESHOLD), "True"]
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts["hardpack"] == "hardpack.cli:console_main"


def test_every_workflow_script_sets_up_its_job_process():
    """The Snakemake scripts are job processes too (hardpack.process.job_process: their log file
    and the collector of a process that ends after one job)."""
    scripts = sorted((ROOT / "workflow" / "scripts").glob("*.py"))
    assert len(scripts) > 30
    for script in scripts:
        assert "job_process(snakemake.log[0])" in script.read_text(), script.name


def test_help_and_unknown_commands_still_list_every_command():
    out = subprocess.run([sys.executable, "-m", "hardpack.cli", "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "glass-entropy" in out.stdout and "compress" in out.stdout
    bad = subprocess.run([sys.executable, "-m", "hardpack.cli", "-q", "no-such-command"], capture_output=True,
                         text=True)
    assert bad.returncode == 2 and "invalid choice" in bad.stderr and "bcmd-ladder" in bad.stderr
