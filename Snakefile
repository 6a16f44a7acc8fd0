# hardpack: the studies as one Snakemake DAG.
#   snakemake --cores all                                  full study (config/config.yaml)
#   snakemake --cores 2 --configfile config/smoke.yaml     tiny systems, same DAG (CI)
#   snakemake --cores 1 results/figures/<name>.pdf         one figure and only what it needs
# Rules are thin: they call the `hardpack` CLI or a short script under workflow/scripts/.

import json

from snakemake.utils import validate

from hardpack.distributions import from_spec

# --configfile replaces the default study instead of being merged into it
if not config:
    configfile: "config/config.yaml"

validate(config, "workflow/schemas/config.schema.yaml")
for _name, _ens in config["ensembles"].items():
    try:
        from_spec(_ens["distribution"])
    except ValueError as exc:
        raise ValueError(f"config: ensembles.{_name}.distribution: {exc}") from None

ENSEMBLES = config["ensembles"]

report: "workflow/report/workflow.rst"

# Registries the study files fill: the figures `rule all` builds, and the summaries the validation
# report reads, by row-builder name (hardpack.validation.cli.ROW_BUILDERS) -> list of paths.
FIGURES = []
VALIDATION_INPUTS = {}


def checkpoint_beside(wildcards, output):
    """params function: the checkpoint of a resumable job, beside its first output (.nc -> .ckpt);
    a killed job started again resumes from it, and the job removes it when it succeeds."""
    return output[0].removesuffix(".nc") + ".ckpt"


wildcard_constraints:
    ensemble="[A-Za-z][A-Za-z0-9_]*",
    seed=r"\d+",


include: "workflow/rules/ensembles.smk"
include: "workflow/rules/md.smk"
include: "workflow/rules/jamming.smk"
include: "workflow/rules/structure.smk"
include: "workflow/rules/slp.smk"
include: "workflow/rules/freeenergy.smk"
include: "workflow/rules/polydisperse.smk"
include: "workflow/rules/validation.smk"


rule all:
    input:
        expand("results/ensembles/{ensemble}/init_summary.nc", ensemble=ENSEMBLES),
        expand("results/ensembles/{ensemble}/jammed_summary.nc", ensemble=ENSEMBLES),
        expand("results/ensembles/{ensemble}/jamming_summary.nc", ensemble=ENSEMBLES),
        expand("results/ensembles/{ensemble}/slp_jamming_summary.nc",
               ensemble=config.get("slp", {}).get("mrj", {}).get("ensembles", [])),
        FIGURES,
        "results/validation/gate.txt",
