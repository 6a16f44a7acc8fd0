# Study 5: structure of the jammed packings: g2 near contact and Z(l), S(k), order metrics.


rule structure:
    """Structure analysis of one LS packing, rattlers from its jamming verdict."""
    input:
        packing="results/ensembles/{ensemble}/jammed/seed{seed}.nc",
        jamming="results/ensembles/{ensemble}/jamming/seed{seed}.nc",
    output:
        "results/ensembles/{ensemble}/structure/seed{seed}.nc",
    threads: 1
    resources:
        mem_mb=lambda w: 1000 + ENSEMBLES[w.ensemble]["N"],
        runtime=lambda w: 10 + ENSEMBLES[w.ensemble]["N"] // 500,
    log:
        "results/logs/structure/{ensemble}_seed{seed}.log",
    shell:
        "hardpack structure {input.packing} --jamming {input.jamming} --out {output} 2> {log}"


STRUCTURE_FILES = [f"results/ensembles/{e}/structure/seed{s}.nc" for e in ENSEMBLES for s in ENSEMBLES[e]["seeds"]]


rule fig_structure:
    """Structure figures of the LS packings: g2 near contact (split second peak), log-log Z(l), S(k) at small k, channel-size histograms."""
    input:
        STRUCTURE_FILES,
    output:
        pdf="results/figures/structure_{kind}.pdf",
        png=report("results/figures/structure_{kind}.png", caption="../report/structure.rst", category="5 structure"),
    wildcard_constraints:
        kind="g2|zl|sk|channels",
    params:
        kind=lambda w: w.kind,
    log:
        "results/logs/figures/structure_{kind}.log",
    script:
        "../scripts/plot_structure.py"


FIGURES += expand("results/figures/structure_{kind}.pdf", kind=["g2", "zl", "sk", "channels"])
VALIDATION_INPUTS["structure"] = STRUCTURE_FILES
