"""Config files against the JSON schema; the Snakemake DAG builds for both configs."""

import copy
import shutil
import subprocess
from pathlib import Path

import jsonschema
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = yaml.safe_load((ROOT / "workflow/schemas/config.schema.yaml").read_text())


def load(name):
    return yaml.safe_load((ROOT / "config" / name).read_text())


def errors(cfg):
    validator = jsonschema.Draft202012Validator(SCHEMA)
    return [f"{'.'.join(map(str, e.absolute_path))}: {e.message}" for e in validator.iter_errors(cfg)]


@pytest.mark.parametrize("name", ["config.yaml", "smoke.yaml"])
def test_shipped_configs_are_valid(name):
    assert errors(load(name)) == []


@pytest.mark.parametrize(
    "mutate, expected",
    [
        (lambda c: c.update(typo_key=1), "'typo_key' was unexpected"),
        (lambda c: c["ensembles"]["mono3d"].update(growthrate=0.1), "ensembles.mono3d: Additional properties.*'growthrate'"),
        (lambda c: c["ensembles"]["mono3d"].update(d=7), "ensembles.mono3d.d: 7 is greater than the maximum of 6"),
        (lambda c: c["ensembles"]["mono3d"].update(N="many"), "ensembles.mono3d.N: 'many' is not of type 'integer'"),
        (lambda c: c["ensembles"]["mono3d"].update(seeds=[1, 1]), "ensembles.mono3d.seeds: .*non-unique"),
        (lambda c: c["ensembles"]["mono3d"].pop("init_phi"), "ensembles.mono3d: 'init_phi' is a required property"),
        (lambda c: c["ensembles"]["mono3d"]["distribution"].update(kind="gaussian"), "distribution.kind: 'gaussian' is not one of"),
        (lambda c: c["ensembles"]["mono3d"].update(distribution={"kind": "uniform_size"}), "distribution: 'omega' is a required property"),
        (lambda c: c["ensembles"].update({"3bad": c["ensembles"]["mono3d"]}), "'3bad' does not match"),
        (lambda c: c["slp"]["diluted"].update(fractoin=0.01), "slp.diluted: Additional properties.*'fractoin'"),
        (lambda c: c["slp"]["diluted"].update(rounds=0), "slp.diluted.rounds: 0 is less than the minimum of 1"),
        (lambda c: c["slp"]["diluted"].pop("fraction"), "slp.diluted: 'fraction' is a required property"),
        (lambda c: c["slp"]["mrj"]["systems"]["slp_poly2d"].update(distribution={"kind": "uniform_size"}),
         "distribution: 'omega' is a required property"),
    ],
)
def test_bad_configs_are_refused_naming_the_key(mutate, expected):
    cfg = copy.deepcopy(load("smoke.yaml"))
    mutate(cfg)
    found = errors(cfg)
    assert found, "the schema accepted a bad config"
    assert any(__import__("re").search(expected, e) for e in found), found


@pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")
def test_snakemake_dry_run_lists_the_dag(tmp_path):
    out = subprocess.run(["snakemake", "-n", "--forceall", "--configfile", "config/smoke.yaml"], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "init_packing" in out.stdout and "fig_size_distributions" in out.stdout


@pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")
def test_snakemake_refuses_unknown_config_key(tmp_path):
    cfg = load("smoke.yaml")
    cfg["ensembles"]["mono3d"]["grwoth_rate"] = 0.1
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(cfg))
    out = subprocess.run(["snakemake", "-n", "--configfile", str(bad)], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode != 0
    assert "grwoth_rate" in out.stdout + out.stderr


@pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")
@pytest.mark.parametrize("mutate, expected", [
    (lambda c: c["slp"]["diluted"].update(ensemble="uv3d_w4"), "must be one of slp.mrj.ensembles"),
    (lambda c: c["slp"]["diluted"].update(seeds=[1, 7]), r"slp.diluted.seeds \[7\] are not seeds"),
])
def test_snakemake_refuses_a_diluted_study_without_its_mrj_packings(tmp_path, mutate, expected):
    cfg = load("smoke.yaml")
    mutate(cfg)
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(cfg))
    out = subprocess.run(["snakemake", "-n", "--configfile", str(bad)], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode != 0
    assert __import__("re").search(expected, out.stdout + out.stderr), out.stdout + out.stderr
