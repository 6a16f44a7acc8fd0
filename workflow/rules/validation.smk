# Study 6: the validation report, every reproduced number beside the published one. Each study file
# registers its summaries in VALIDATION_INPUTS (row-builder name -> paths); this rule reads them all.


rule validation:
    """results/validation/validation.nc and report.md from every summary the config produces."""
    input:
        [path for paths in VALIDATION_INPUTS.values() for path in paths],
    output:
        nc="results/validation/validation.nc",
        md="results/validation/report.md",
    params:
        inputs=" ".join(f"{name}={path}" for name, paths in VALIDATION_INPUTS.items() for path in paths),
    log:
        "results/logs/validation.log",
    shell:
        "hardpack validate {params.inputs} --out-nc {output.nc} --out-md {output.md} 2> {log}"
