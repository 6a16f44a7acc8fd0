"""The CI script runs the README's test command and stops on any failed step."""

import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]


def _readme_commands():
    """The commands of the README's set-up section (other sections, e.g. the cluster's, are not set-up)."""
    section = (ROOT / "README.md").read_text().split("## Set-up on a fresh machine", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```bash\n(.+?)\n```", section)


def test_readme_has_exactly_two_setup_commands():
    commands = _readme_commands()
    assert len(commands) == 2, commands
    assert commands[0].startswith("python -m pip install -e . && snakemake")
    assert commands[1] == 'python -m pip install -e ".[test]" && python -m pytest'


def test_readme_says_how_to_go_on_after_a_killed_run():
    """A killed Snakemake leaves its lock on the working directory: the README names the way out."""
    text = " ".join((ROOT / "README.md").read_text().split())
    after_kill = text.split("After a killed run", 1)[1].split("- **", 1)[0]
    assert "snakemake --unlock" in after_kill and "--rerun-incomplete" in after_kill


def test_ci_runs_the_readme_test_command_and_stops_if_its_install_fails(tmp_path):
    script = (ROOT / ".ci" / "run").read_text()
    test_command = _readme_commands()[1]
    line = next(line for line in script.splitlines() if line.startswith(test_command))
    assert script.startswith("#!/usr/bin/env bash") and "set -euo pipefail" in script
    # the same line with a failing install must stop a `set -e` script before its next step
    probe = tmp_path / "probe.sh"
    failing = line.replace('python -m pip install -e ".[test]"', "false").replace("python -m pytest", "true")
    probe.write_text(f"set -euo pipefail\n{failing}\necho next-step\n")
    result = subprocess.run(["bash", str(probe)], capture_output=True, text=True)
    assert result.returncode != 0 and "next-step" not in result.stdout
    # the bare `a && b` form (the old script) would have gone on
    probe.write_text("set -euo pipefail\nfalse && true\necho next-step\n")
    assert "next-step" in subprocess.run(["bash", str(probe)], capture_output=True, text=True).stdout


def test_ci_starts_the_smoke_dag_from_an_empty_results_directory_and_gates_it():
    script = (ROOT / ".ci" / "run").read_text()
    clean = script.index("git clean -fdxq -- results/")
    smoke = script.index("snakemake --cores 2 --configfile config/smoke.yaml")
    assert clean < smoke
    assert "hardpack validate --check results/validation/validation.nc" in script
    snakefile = (ROOT / "Snakefile").read_text()
    common = (ROOT / "workflow" / "rules" / "common.smk").read_text()
    # `rule all` takes final_outputs(), which ends with the gate
    assert "final_outputs()" in snakefile and 'outputs.append("results/validation/gate.txt")' in common


def _slurm_jobs_module():
    import importlib.util

    spec = importlib.util.spec_from_file_location("slurm_jobs", ROOT / ".ci" / "slurm_jobs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_slurm_job_check_counts_group_members_when_executor_messages_interleave(tmp_path):
    """The SLURM executor may print a message between the members of a group job's list (CI saw
    "Both 'sacctmgr' and 'sshare' returned empty results ..."); the members after it still count."""
    member = "    [Thu Nov 26 07:11:48 2026]\n    rule combine:\n        input: a.nc\n        output: {out}\n"
    snakemake_log = (
        "Job stats:\njob        count\n-------  -------\ncombine        3\nverify         1\ntotal          4\n\n"
        "Job 7 has been submitted with SLURM jobid 11 (log: /x/.snakemake/slurm_logs/rule_verify/s1/11.log).\n"
        "[Thu Nov 26 07:11:48 2026] Group job summaries (jobs in lexicogr. order):\n\n"
        + member.format(out="s1.nc") + member.format(out="s2.nc")
        + "Both 'sacctmgr' and 'sshare' returned empty results for account 'none'.\n"
        + member.format(out="s3.nc")
        + "Job abc has been submitted with SLURM jobid 12 (log: /x/.snakemake/slurm_logs/group_summaries_combine/12.log).\n"
    )
    ctld_log = "".join(f"_slurm_rpc_submit_batch_job: JobId={j}\n_job_complete: JobId={j} WEXITSTATUS 0\n"
                       for j in (11, 12))
    (tmp_path / "snakemake.log").write_text(snakemake_log)
    (tmp_path / "ctld.log").write_text(ctld_log)
    check = _slurm_jobs_module()
    check.main(str(tmp_path / "snakemake.log"), str(tmp_path / "ctld.log"))  # no SystemExit
    (tmp_path / "ctld.log").write_text(ctld_log.replace("JobId=12 WEXITSTATUS 0", "JobId=12 WEXITSTATUS 1"))
    with pytest.raises(SystemExit, match="did not complete"):
        check.main(str(tmp_path / "snakemake.log"), str(tmp_path / "ctld.log"))


def test_slurm_subset_deletes_one_output_per_rule_and_the_validation(tmp_path):
    summary = tmp_path / "summary.tsv"
    summary.write_text(
        "output_file\tdate\trule\tlog-file(s)\tstatus\tplan\n"
        "results/a/init/seed1.nc\tThu Nov 26 09:17:07 2026\tinit\t-\tok\tno update\n"
        "results/a/init/seed2.nc\tThu Nov 26 09:17:08 2026\tinit\t-\tok\tno update\n"
        "results/a/jammed/seed1.nc\tThu Nov 26 09:18:00 2026\tcompress\t-\tok\tno update\n"
        "results/validation/gate.txt\tThu Nov 26 09:19:00 2026\tvalidation\t-\tok\tno update\n")
    run = tmp_path / "run"
    for name in ("a/init/seed1.nc", "a/init/seed2.nc", "a/jammed/seed1.nc", "validation/gate.txt",
                 "validation/report.md"):
        (run / "results" / name).parent.mkdir(parents=True, exist_ok=True)
        (run / "results" / name).write_text("x")
    no_records = tmp_path / "metadata"
    out = subprocess.run(["python", str(ROOT / ".ci" / "slurm_subset.py"), str(summary), str(run), str(no_records)],
                         capture_output=True, text=True, check=True).stdout.split()
    assert out == ["results/a/init/seed1.nc", "results/a/jammed/seed1.nc", "results/validation/gate.txt"]
    assert not (run / "results" / "validation").exists()
    assert not (run / "results/a/init/seed1.nc").exists() and not (run / "results/a/jammed/seed1.nc").exists()
    assert (run / "results/a/init/seed2.nc").exists()


def _subset_records(tmp_path, jobs):
    """.ci/slurm_subset.py as a module, and a `snakemake --summary` table and Snakemake records of
    a local run of ``jobs`` ({output: (rule, start, end, inputs)}) in tmp_path."""
    import base64
    import json

    sys.path.insert(0, str(ROOT / ".ci"))
    try:
        import slurm_subset
    finally:
        sys.path.pop(0)
    metadata = tmp_path / "metadata"
    metadata.mkdir()
    for output, (rule, start, end, inputs) in jobs.items():
        record = metadata / base64.urlsafe_b64encode(output.encode()).decode()
        record.write_text(json.dumps({"rule": rule, "starttime": start, "endtime": end, "input": inputs,
                                      "job_hash": hash(output)}))
    summary = tmp_path / "summary.tsv"
    summary.write_text("output_file\tdate\trule\n" + "".join(f"{o}\t-\t{j[0]}\n" for o, j in jobs.items()))
    return slurm_subset, str(summary), metadata


def test_slurm_subset_covers_every_rule_with_the_cheapest_reruns(tmp_path):
    """With Snakemake's records of the local run, deleting an output reruns its job and every job
    downstream: the quick init whose compression is slow (101 s) loses to the slower init whose
    compression is quick (12 s), and that one deletion covers both rules."""
    jobs = {  # output: (rule, start, end, inputs)
        "results/a/init/seed1.nc": ("init", 0.0, 1.0, []),
        "results/a/init/seed2.nc": ("init", 0.0, 2.0, []),
        "results/a/jammed/seed1.nc": ("compress", 2.0, 102.0, ["results/a/init/seed1.nc"]),
        "results/a/jammed/seed2.nc": ("compress", 2.0, 12.0, ["results/a/init/seed2.nc"]),
    }
    slurm_subset, summary, metadata = _subset_records(tmp_path, jobs)
    picks = slurm_subset.one_output_per_kind(summary, metadata)
    assert set(picks.values()) == {"results/a/init/seed2.nc"}
    reruns = slurm_subset.rerun_jobs("results/a/init/seed2.nc", *slurm_subset.local_jobs(metadata)[::2])
    assert {job[0] for job in reruns} == {"init", "compress"}
    assert slurm_subset.rerun_cost("results/a/init/seed1.nc", *slurm_subset.local_jobs(metadata)) == 101.0


def test_slurm_subset_covers_every_kind_of_job(tmp_path):
    """With kinds (job groups, compute rules), each kind is covered once at the least cost: the
    lattice (setup, 1 s) and the compression of seed 2 (compute, 10 s); no init, no slow
    compression of seed 1, and not every rule."""
    jobs = {  # output: (rule, start, end, inputs)
        "results/a/init/seed1.nc": ("init", 0.0, 1.0, []),
        "results/a/init/seed2.nc": ("init", 0.0, 2.0, []),
        "results/a/jammed/seed1.nc": ("compress", 2.0, 102.0, ["results/a/init/seed1.nc"]),
        "results/a/jammed/seed2.nc": ("compress", 2.0, 12.0, ["results/a/init/seed2.nc"]),
        "results/a/other.nc": ("lattice", 0.0, 1.0, []),
    }
    slurm_subset, summary, metadata = _subset_records(tmp_path, jobs)
    kinds = slurm_subset.rule_kinds(ROOT / "workflow" / "rules")
    profile = yaml.safe_load((ROOT / "workflow/profiles/slurm/config.yaml").read_text())
    assert set(kinds.values()) == set(profile["group-components"]) | {"shell"}
    assert kinds["init"] == "setup" and kinds["compress"] == "shell" and kinds["validation"] == "validation"
    picks = slurm_subset.one_output_per_kind(summary, metadata, kinds)
    assert picks == {"setup": "results/a/other.nc", "shell": "results/a/jammed/seed2.nc"}


def test_slurm_smoke_sizes_every_group_of_the_profile():
    """--group-components on the command line replaces the profile's whole mapping: the CI run
    must name every group of the profile, or the missing ones would run one job per cluster job."""
    profile = yaml.safe_load((ROOT / "workflow/profiles/slurm/config.yaml").read_text())
    script = (ROOT / ".ci" / "slurm-smoke").read_text()
    sizes = dict(item.split("=") for item in re.search(r"--group-components ((?:\w+=\d+ ?)+)", script).group(1).split())
    assert set(sizes) == set(profile["group-components"])
