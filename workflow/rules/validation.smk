# Study 6: the validation report, every reproduced number beside the published one.


rule validation:
    """results/validation/validation.nc and report.md from every summary the config produces."""
    input:
        slp_densest="results/slp/densest_summary.nc" if SLP_DENSEST else [],
        ls=expand("results/ensembles/{ensemble}/jammed_summary.nc", ensemble=ENSEMBLES),
        slp_mrj=expand("results/ensembles/{ensemble}/slp_summary.nc", ensemble=SLP_MRJ["ensembles"])
        if SLP_MRJ else [],
        bcmd=expand("results/freeenergy/{state}_summary.nc", state=["melting", "jamming"]) if FREEENERGY else [],
    output:
        nc="results/validation/validation.nc",
        md="results/validation/report.md",
    params:
        slp=lambda w, input: f"--slp-densest {input.slp_densest}" if input.slp_densest else "",
        ls=lambda w, input: " ".join(f"--ls-summary {p}" for p in input.ls),
        slp_mrj=lambda w, input: " ".join(f"--slp-summary {p}" for p in input.slp_mrj),
        bcmd=lambda w, input: " ".join(f"--bcmd-summary {p}" for p in input.bcmd),
    log:
        "results/logs/validation.log",
    shell:
        "hardpack validate --out-nc {output.nc} --out-md {output.md} {params.slp} {params.ls}"
        " {params.slp_mrj} {params.bcmd} 2> {log}"
