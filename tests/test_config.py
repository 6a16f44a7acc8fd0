"""Config files against the JSON schema; the Snakemake DAG builds for both configs."""

import copy
import re
import shlex
import shutil
import subprocess
from pathlib import Path

import jsonschema
import pytest
import yaml

from hardpack.config import check_config, validate_schema
from hardpack.errors import InvalidInputError

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


def test_validate_schema_fills_defaults_and_names_the_key_it_refuses():
    """The workflow's validator (hardpack.config.validate_schema) against jsonschema's reference
    validator above: the same verdicts, plus the schema's defaults filled in."""
    schema = ROOT / "workflow/schemas/config.schema.yaml"
    cfg = load("smoke.yaml")
    cfg["validation"].pop("min_applicable", None)
    validate_schema(cfg, schema)
    assert cfg["validation"]["min_applicable"] == 30
    cfg["ensembles"]["mono3d"]["grwoth_rate"] = 0.1
    assert errors(cfg)
    with pytest.raises(InvalidInputError, match=r"'grwoth_rate' was unexpected\) \(at ensembles.mono3d;"):
        validate_schema(cfg, schema)
    cfg = load("smoke.yaml")
    cfg["glass"]["N"] = "many"
    with pytest.raises(InvalidInputError, match="'many' is not of type 'integer' \\(at glass.N;"):
        validate_schema(cfg, schema)


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
        (lambda c: c["containers"].update(radius=3), "containers: Additional properties.*'radius'"),
        (lambda c: c["containers"].update(N=[100]), r"containers.N: \[100\] should be non-empty|too short"),
        (lambda c: c["containers"].pop("core_margin"), "containers: 'core_margin' is a required property"),
        (lambda c: c["ellipsoid_containers"].pop("shell_width"),
         "ellipsoid_containers: 'shell_width' is a required property"),
        (lambda c: c["containers"]["windows"].update(n_windows=1), "containers.windows.n_windows: 1 is less than"),
        (lambda c: c["ellipsoid_crystals"]["search"].update(n=[0]), "ellipsoid_crystals.search.n.0: 0 is less than"),
        (lambda c: c["ellipsoid_crystals"]["search"].update(alphas=[1.5, 1.5]), "ellipsoid_crystals.search.alphas: .*non-unique"),
        (lambda c: c["ellipsoids"].update(ascent_max_particles=-1), "ellipsoids.ascent_max_particles: -1 is less than"),
        (lambda c: c["ellipsoids"].update(ascent_max_particles=1.5),
         "ellipsoids.ascent_max_particles: 1.5 is not of type 'integer'"),
    ],
)
def test_bad_configs_are_refused_naming_the_key(mutate, expected):
    cfg = copy.deepcopy(load("smoke.yaml"))
    mutate(cfg)
    found = errors(cfg)
    assert found, "the schema accepted a bad config"
    assert any(__import__("re").search(expected, e) for e in found), found


def _every_hardpack_command_parses(listing):
    """Every `hardpack` shell command of a dry run's listing (-p) passes the command line's parser.
    (A negative number in exponent notation, `--growth-rate -1e-05`, reads as an option: the full
    study's glass decompression failed so, while the smoke's `-0.001` parsed.)"""
    from hardpack.cli import build_parser

    commands = [line.split("Shell command: ", 1)[1] for line in listing.splitlines()
                if line.startswith("Shell command: hardpack ")]
    assert len(commands) > 10, listing[-2000:]
    parsers = {}
    for command in commands:
        words = shlex.split(command)
        words = words[:next((k for k, w in enumerate(words) if w in {">", "|", "&&", ";", "2>&1"}), len(words))]
        if words[1] not in parsers:
            parsers[words[1]] = build_parser(words[1])
        parser = parsers[words[1]]
        try:
            parser.parse_args(words[1:])
        except SystemExit:
            pytest.fail(f"the command line's parser refuses: {command}")


@pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")
@pytest.mark.parametrize("configfile", ["config/config.yaml", "config/smoke.yaml"])
def test_snakemake_dry_run_lists_the_dag(configfile):
    out = subprocess.run(["snakemake", "-n", "-p", "--forceall", "--configfile", configfile], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    _every_hardpack_command_parses(out.stdout)
    assert re.search(r"^init +\d+$", out.stdout, re.M) and "fig_size_distributions" in out.stdout
    ellipsoids = load(configfile.split("/")[1])["ellipsoids"]
    near = ellipsoids.get("near_sphere")
    if near:  # the near-sphere packings take their own final rate, the others the study's
        compress = [line for line in out.stdout.splitlines() if line.startswith("Shell command: hardpack compress")
                    and "results/ellipsoids/" in line]
        near_final = near.get("final_growth_rate", ellipsoids["final_growth_rate"])
        for line in compress:
            final = near_final if "results/ellipsoids/near_" in line else ellipsoids["final_growth_rate"]
            assert f"--final-growth-rate {final} " in line, line
        assert any("results/ellipsoids/near_" in line for line in compress)
    cfg = load(configfile.split("/")[1])["containers"]
    packings = len(cfg["N"]) * len(cfg["seeds"])
    bulk = len(cfg["bulk"]["seeds"])  # the periodic packings of the protocol start like the containers
    for rule, count in (("container_init", packings + bulk), ("container_profile", packings), ("container_summary", 1),
                        ("container_windows", 1), ("fig_container_profile", 1), ("fig_container_extrapolation", 1),
                        ("fig_container_windows", 1)):
        assert re.search(rf"^{rule} +{count}$", out.stdout, re.M), rule
    ell = load(configfile.split("/")[1])["ellipsoid_containers"]
    shapes = len(ell["shapes"])
    for rule, count in (("ellipsoid_container_profile", shapes * len(ell["N"]) * len(ell["seeds"])),
                        ("ellipsoid_container_summary", shapes), ("fig_ellipsoid_container_profile", 1)):
        assert re.search(rf"^{rule} +{count}$", out.stdout, re.M), rule


@pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")
def test_the_ascent_limit_reaches_the_verify_commands(tmp_path):
    """``ellipsoids.ascent_max_particles`` (optional) becomes every ellipsoid verdict's
    --ascent-max-particles; without it the commands leave the library's default."""
    from hardpack.cli import build_parser

    cfg = copy.deepcopy(load("smoke.yaml"))
    cfg["ellipsoids"]["ascent_max_particles"] = 1000
    path = tmp_path / "ascent.yaml"
    path.write_text(yaml.safe_dump(cfg))
    for configfile, flag in ((path, "--ascent-max-particles 1000 "), (ROOT / "config" / "smoke.yaml", None)):
        out = subprocess.run(["snakemake", *_verdict_targets(cfg), "-n", "-p", "--forceall", "--configfile",
                              str(configfile)], cwd=ROOT, capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, out.stderr
        verify = [line for line in out.stdout.splitlines() if line.startswith("Shell command: hardpack verify")]
        assert verify and all((flag in line) if flag else ("--ascent-max-particles" not in line) for line in verify)
        for line in verify:  # the command line's parser takes them
            words = shlex.split(line.split("Shell command: ", 1)[1])
            build_parser("verify").parse_args(words[1:words.index(">")])


def _verdict_targets(cfg):
    """The verdict files of the smoke config's ellipsoid study (the main grid's first family)."""
    family = next(iter(cfg["ellipsoids"]["families"]))
    alpha = cfg["ellipsoids"]["alphas"][0]
    return [f"results/ellipsoids/{family}_a{alpha:g}/verdict/seed{cfg['ellipsoids']['seeds'][0]}.nc"]


@pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")
def test_snakemake_lint_finds_nothing():
    """`snakemake --lint` exits non-zero on any finding (rules mixed with functions, a rule without
    log or software environment, hard-coded path prefixes in params, ...). The lints read the rules,
    which both configs share (no rule file is included conditionally), so one config suffices."""
    out = subprocess.run(["snakemake", "--lint", "--configfile", "config/smoke.yaml"], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and "Lints for" not in out.stdout + out.stderr, out.stdout + out.stderr


def test_every_rule_logs_and_benchmarks_by_its_name(workflow_rules):
    """One log convention and one benchmark convention: results/logs/{rule}/... and
    results/benchmarks/{rule}/... (or {rule}.log / {rule}.tsv without wildcards)."""
    rules = workflow_rules
    assert {"init", "compress", "slp", "verify", "structure", "combine", "validation"} <= set(rules)
    for name, text in rules.items():
        for directive, folder, suffix in (("log", "logs", "log"), ("benchmark", "benchmarks", "tsv")):
            match = re.search(rf"^    {directive}:\n        \"([^\"]+)\"", text, re.M)
            assert match, f"rule {name} has no {directive} directive"
            assert re.fullmatch(rf"results/{folder}/{name}(/.+)?\.{suffix}", match.group(1)), (name, match.group(1))


def test_pipeline_times_sums_the_benchmark_files_per_rule(tmp_path):
    import importlib.util

    spec = importlib.util.spec_from_file_location("pipeline_times", ROOT / "benchmarks" / "pipeline_times.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    header = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
    files = {"verify/ls/mono3d/seed1.tsv": "12.5\t0:00:12\t1\t1\t1\t1\t0\t0\t90\t11.0\n",
             "verify/slp_diluted/mono3d/seed1/round2.tsv": "7.5\t0:00:07\t1\t1\t1\t1\t0\t0\t90\t6.0\n",
             "validation.tsv": "1.0\t0:00:01\t1\t1\t1\t1\t0\t0\t90\t0.5\n"}
    for name, line in files.items():
        path = tmp_path / "results" / "benchmarks" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(header + line)
    times = module.job_times(tmp_path)
    assert sorted(times) == ["validation", "verify"]
    assert sorted(times["verify"]) == [(7.5, 6.0), (12.5, 11.0)] and times["validation"] == [(1.0, 0.5)]


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


@pytest.mark.parametrize("mutate, expected", [
    (lambda c: c["slp"]["diluted"].update(ensemble="uv3d_w4"), "must be one of slp.mrj.ensembles"),
    (lambda c: c["slp"]["diluted"].update(seeds=[1, 7]), r"slp.diluted.seeds \[7\] are not seeds"),
    (lambda c: c["slp"]["mrj"].update(ensembles=["nope"]), "slp.mrj.ensembles names 'nope'"),
    (lambda c: c["freeenergy"]["simplex"].update(ensemble="mono9d"), r"freeenergy.simplex.ensemble 'mono9d' is not one"),
    (lambda c: c["freeenergy"]["simplex"].update(seeds=[1, 7]), r"freeenergy.simplex.seeds \[7\] are not seeds"),
    (lambda c: c["rates"].update(ensemble="mono9d"), "rates.ensemble 'mono9d' is not one of the ensembles"),
    (lambda c: c["ls_densest"]["runs"].append(dict(c["ls_densest"]["runs"][0])), "ls_densest.runs lists a dimension twice"),
    (lambda c: c["glass"].update(N=c["glass"]["N"] + 1), "glass.N = .* must be even"),
    (lambda c: c["glass"].update(phi_end=0.5), "glass.phi_end must be above every glass.snapshots"),
    (lambda c: c["glass"].update(slow={"rate": 1.0, "from_phi": 0.70}), r"glass.slow.rate = 1 must be below every"),
    (lambda c: c["glass"].update(slow={"rate": 1e-9, "from_phi": 0.71}), r"glass.slow.from_phi = 0.71 must be one of"),
    (lambda c: c["glass"]["relaxation"].update(phi=0.79), r"glass.relaxation.phi = 0.79 must be one of"),
    (lambda c: c["glass"]["separated"].update(phi_end=0.85), "glass.separated.phi_end must lie below"),
    (lambda c: c["glass"]["mono"]["crystal_bcmd"].update(phis=[0.75, 0.89]), "crystal_bcmd.phis must lie below"),
    (lambda c: c["ellipsoids"].update(near_sphere={"families": ["cube"]}), r"near_sphere.families \['cube'\]"),
    (lambda c: c["ellipsoids"]["mm"].update(family="cube"), "ellipsoids.mm.family 'cube' is not one of"),
    (lambda c: c["containers"]["windows"].update(ensemble="binary2d"), "must be a monodisperse 3D ensemble"),
    (lambda c: c["containers"].update(core_margin=6), "core_margin = 6 a leaves no core"),
    (lambda c: c["ellipsoid_containers"].update(core_margin=4), "ellipsoid_containers.core_margin = 4 a leaves no core"),
    (lambda c: c["containers"].update(fit_min_n=200), "fewer than 2 container sizes"),
    (lambda c: c["containers"]["windows"].update(fit_min_diameter=0.1), "fit_min_diameter must be >= min_diameter"),
    (lambda c: c["ellipsoid_crystals"]["search"].update(alphas=[1.5, 1.0]), r"ellipsoid_crystals.search.alphas contains 1"),
])
def test_contradicting_sections_are_refused_naming_the_key(mutate, expected):
    cfg = copy.deepcopy(load("smoke.yaml"))
    assert errors(cfg) == []
    check_config(copy.deepcopy(cfg))
    mutate(cfg)
    with pytest.raises(InvalidInputError, match=expected):
        check_config(cfg)


@pytest.mark.parametrize("name", ["config.yaml", "smoke.yaml"])
def test_shipped_configs_pass_the_cross_checks(name):
    check_config(load(name))


@pytest.mark.skipif(shutil.which("snakemake") is None, reason="snakemake not installed")
def test_snakemake_refuses_a_study_without_its_input_packings(tmp_path):
    """The workflow runs the cross-reference checks (one case end to end; the others above)."""
    cfg = load("smoke.yaml")
    cfg["slp"]["diluted"].update(seeds=[1, 7])
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(cfg))
    out = subprocess.run(["snakemake", "-n", "--configfile", str(bad)], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode != 0
    assert re.search(r"slp.diluted.seeds \[7\] are not seeds", out.stdout + out.stderr), out.stdout + out.stderr
