# Study 5: structure of the jammed packings: g2 near contact and Z(l), S(k), order metrics.


rule structure:
    """Structure analysis of one LS packing, rattlers from its jamming verdict."""
    input:
        packing="results/ensembles/{ensemble}/jammed/seed{seed}.nc",
        jamming="results/ensembles/{ensemble}/jamming/seed{seed}.nc",
    output:
        "results/ensembles/{ensemble}/structure/seed{seed}.nc",
    log:
        "results/logs/structure/{ensemble}_seed{seed}.log",
    shell:
        "hardpack structure {input.packing} --jamming {input.jamming} --out {output} 2> {log}"
