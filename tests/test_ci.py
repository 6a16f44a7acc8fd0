"""The CI script runs the README's test command and stops on any failed step."""

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _readme_commands():
    return re.findall(r"```bash\n(.+?)\n```", (ROOT / "README.md").read_text())


def test_readme_has_exactly_two_setup_commands():
    commands = _readme_commands()
    assert len(commands) == 2, commands
    assert commands[0].startswith("python -m pip install -e . && snakemake")
    assert commands[1] == 'python -m pip install -e ".[test]" && python -m pytest'


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
