# Study 6: the validation report, every reproduced number beside its published target
# (src/hardpack/validation/targets.yaml), and the gate. Each study file registers its summaries in
# VALIDATION_INPUTS (row-builder name -> paths). The report is written first and the gate runs as
# its own rule, so that a failing gate keeps the report to read.

VALIDATION = config.get("validation", {})


rule validation_report:
    """results/validation/validation.nc and report.md from every summary the config produces."""
    input:
        [path for paths in VALIDATION_INPUTS.values() for path in paths],
    output:
        nc="results/validation/validation.nc",
        md="results/validation/report.md",
    params:
        inputs=" ".join(f"{name}={path}" for name, paths in VALIDATION_INPUTS.items() for path in paths),
    log:
        "results/logs/validation_report.log",
    shell:
        "hardpack validate {params.inputs} --out-nc {output.nc} --out-md {output.md} --no-gate 2> {log}"


rule validation:
    """The gate: fails when an applicable row fails, a documented deviation now passes, or fewer
    than validation.min_applicable reproduction and analytic rows apply (see report.md)."""
    input:
        "results/validation/validation.nc",
    output:
        "results/validation/gate.txt",
    params:
        min_applicable=VALIDATION.get("min_applicable", 30),
    log:
        "results/logs/validation_gate.log",
    shell:
        "hardpack validate --check {input} --min-applicable {params.min_applicable} 2> {log}"
        " && echo 'validation gate passed' > {output}"
        " || (cat {log} >&2; exit 1)"
