# The validation report, every reproduced number beside its published target
# (src/hardpack/validation/targets.yaml), and the gate. validation_inputs() in common.smk lists the
# summaries by row builder. The report is written first and the gate runs as its own rule, so that
# a failing gate keeps the report to read.


rule validation_report:
    """results/validation/validation.nc and report.md from every summary the config produces."""
    input:
        [path for paths in validation_inputs().values() for path in paths],
    output:
        nc="results/validation/validation.nc",
        md="results/validation/report.md",
    params:
        inputs=validation_arguments(),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/validation_report.log",
    benchmark:
        "results/benchmarks/validation_report.tsv"
    shell:
        "hardpack validate {params.inputs} --out-nc {output.nc} --out-md {output.md} --no-gate > {log} 2>&1"


rule validation:
    """The gate: fails when an applicable row fails, a documented deviation now passes, or fewer
    than validation.min_applicable reproduction and analytic rows apply (see report.md)."""
    input:
        "results/validation/validation.nc",
    output:
        "results/validation/gate.txt",
    params:
        min_applicable=VALIDATION.get("min_applicable", 30),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/validation.log",
    benchmark:
        "results/benchmarks/validation.tsv"
    shell:
        "hardpack validate --check {input} --min-applicable {params.min_applicable} > {log} 2>&1"
        " && echo 'validation gate passed' > {output}"
        " || (cat {log} >&2; exit 1)"
