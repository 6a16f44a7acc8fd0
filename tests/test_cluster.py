"""Cluster runs: every rule's resources come from the cost model, its limits cover the measured
jobs of the full study, the profiles say what docs/cluster.md says. (A real SLURM run is in .ci/run.)"""

import re
import shutil
import subprocess
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
needs_snakemake = pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")


def _expected_minutes_rules():
    common = (ROOT / "workflow" / "rules" / "common.smk").read_text()
    table = common.split("EXPECTED_MINUTES = {", 1)[1].split("\n}", 1)[0]
    return set(re.findall(r'^    "(\w+)":', table, re.M))


def test_every_rule_takes_its_resources_from_the_cost_model_under_its_own_name(workflow_rules):
    for name, text in workflow_rules.items():
        assert re.search(r"^    threads: \w+$", text, re.M), f"rule {name} sets no threads"
        assert f'mem_mb=job_mem_mb("{name}")' in text, f"rule {name}: mem_mb not from job_mem_mb(\"{name}\")"
        assert f'runtime=job_runtime("{name}")' in text, f"rule {name}: runtime not from job_runtime(\"{name}\")"


def test_a_rule_without_its_own_cost_runs_in_a_job_group_and_the_profile_sizes_every_group(workflow_rules):
    costed = _expected_minutes_rules()
    profile = yaml.safe_load((ROOT / "workflow/profiles/slurm/config.yaml").read_text())
    groups = {}
    for name, text in workflow_rules.items():
        group = re.search(r'^    group:\n        "(\w+)"', text, re.M)
        assert (group is None) == (name in costed), f"rule {name}: grouped rules are the tiny ones, without a cost"
        if group:
            groups[name] = group.group(1)
    assert set(groups.values()) == set(profile["group-components"]), groups


def test_slurm_profile_settings():
    profile = yaml.safe_load((ROOT / "workflow/profiles/slurm/config.yaml").read_text())
    assert profile["executor"] == "slurm" and profile["retries"] >= 1 and profile["rerun-incomplete"]
    assert {"slurm_partition", "slurm_account", "mem_mb", "runtime"} <= set(profile["default-resources"])
    # squeue: without slurmdbd sacct knows no job, and it misses jobs cancelled by scancel
    assert profile["slurm-status-command"] == "squeue"
    assert profile["set-resource-scopes"] == {"group_cores": "local"} and profile["resources"]["group_cores"] == 1


def _dry_run(*args):
    out = subprocess.run(["snakemake", "-n", "--forceall", "--cores", "64", *args], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return out.stdout + out.stderr


def _job_block(text, output):
    """The listing of the job writing ``output`` in a dry run's output."""
    return next(b for b in re.split(r"\n(?=\s*(?:local)?rule \w+:)", text) if f"output: {output}" in b)


def _job_resources(text, output):
    """(threads, runtime, mem_mb) of the job writing ``output`` in a dry run's listing."""
    block = _job_block(text, output)
    threads = re.search(r"^\s*threads: (\d+)", block, re.M)
    resources = re.search(r"resources: .*", block).group(0)
    runtime = int(re.search(r"\bruntime=(\d+)", resources).group(1))
    return (int(threads.group(1)) if threads else 1), runtime, int(re.search(r"\bmem_mb=(\d+)", resources).group(1))


@needs_snakemake
def test_time_limits_cover_the_measured_jobs_of_the_full_study_twice():
    """Measured wall minutes of the longest jobs of each kind (docs/cluster.md: the full study's
    records on the loaded 2-core machine) against the limits of the first attempt."""
    text = _dry_run()
    assert "workflow specific profile" not in text  # workflow/profiles/default is not loaded implicitly
    measured = {
        "results/ls/mono3d_large/jammed/seed1.nc": 58,                          # LS N = 1e4, Gamma_f = 1e-4
        "results/ls_rates/mono3d_gamma0.0003/jammed/seed1.nc": 3.1,             # N = 1000, Gamma = 3e-4
        "results/poly_crystallisation/uniform_size_w10/poly/seed2.nc": 18.3,    # N = 500, Gamma_f = 1e-5
        "results/poly_phij/uniform_size_w1.2/poly/seed2.nc": 1.9,               # N = 1000, Gamma_f = 2e-3
        "results/slp_mrj/mono3d/slp/seed4.nc": 24.3,                            # SLP 3D N = 1000
        "results/slp_mrj/slp_mono6d/slp/seed1.nc": 25,                          # SLP 6D N = 250
        "results/slp_densest/d5/slp/seed0.nc": 6.3,                             # SLP 5D N = 243
        "results/ls/mono3d_large/verdict/seed1.nc": 5,                          # jamming test N = 1e4
        "results/poly_fluid/uniform_volume_w10/fluid.nc": 2.3,
        "results/glass/binary/bcmd/g1e-05/phi0.7/seed2.nc": 2.7,                # glass BCMD N = 4096, thermostat
    }
    for output, minutes in measured.items():
        _, runtime, _ = _job_resources(text, output)
        assert runtime >= 2 * minutes, f"{output}: limit {runtime} min for a job measured at {minutes} min"
    threads, _, mem_mb = _job_resources(text, "results/ls/mono3d_large/verdict/seed1.nc")
    assert threads == 2 and mem_mb >= 3000  # two ~1 GB loading-sequence workers besides the main process


def test_no_job_group_holds_a_job_and_its_input(workflow_rules):
    """Members of one job group must not depend on each other: the slurm profile runs a group's
    connected members as one job step that asks for more CPUs than the cluster job has ("srun:
    Unable to create step ... More processors requested than permitted")."""
    import subprocess

    dot = subprocess.run(["snakemake", "-n", "--forceall", "--dag", "--configfile", "config/smoke.yaml"],
                         cwd=ROOT, capture_output=True, text=True, check=True).stdout
    rule_of = {int(k): v for k, v in re.findall(r'^\s*(\d+)\[label = "(\w+)', dot, re.M)}
    profile = yaml.safe_load((ROOT / "workflow/profiles/slurm/config.yaml").read_text())
    # a chain of single jobs (validation: report -> gate, one component per cluster job) is fine
    chains = {name for name, size in profile["group-components"].items() if size == 1}
    group = {name: m.group(1) for name, text in workflow_rules.items()
             if (m := re.search(r'^    group:\n        "(\w+)"', text, re.M)) and m.group(1) not in chains}
    for a, b in re.findall(r"^\s*(\d+) -> (\d+)", dot, re.M):
        ra, rb = rule_of[int(a)], rule_of[int(b)]
        assert not (ra in group and group.get(rb) == group[ra]), f"{ra} -> {rb} inside group {group[ra]}"


@needs_snakemake
def test_glass_bcmd_runs_with_the_thermostat_and_a_limit_for_it():
    """glass.bcmd.reset_ratio reaches `hardpack bcmd`, and the cost model prices the run with the
    thermostat (~5 min at N = 4096) rather than without it (~3 h: kT ~ 1 / dmu^2)."""
    output = "results/glass/binary/bcmd/g1e-05/phi0.8/seed1.nc"
    text = _dry_run("-p", output)
    assert "--reset-ratio 2 " in _job_block(text, output)
    _, runtime, _ = _job_resources(text, output)
    assert 4 <= runtime <= 30
