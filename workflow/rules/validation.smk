# Study 6: the validation report, every reproduced number beside the published one.


rule validation:
    """results/validation/validation.nc and report.md from every summary the config produces."""
    input:
        slp_densest="results/slp/densest_summary.nc" if SLP_DENSEST else [],
    output:
        nc="results/validation/validation.nc",
        md="results/validation/report.md",
    params:
        slp=lambda w, input: f"--slp-densest {input.slp_densest}" if input.slp_densest else "",
    log:
        "results/logs/validation.log",
    shell:
        "hardpack validate --out-nc {output.nc} --out-md {output.md} {params.slp} 2> {log}"
