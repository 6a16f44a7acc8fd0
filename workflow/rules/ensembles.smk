# Study 1 (generation): per-seed start configurations and their ensemble summary.


def init_files(wildcards):
    seeds = ENSEMBLES[wildcards.ensemble]["seeds"]
    return expand("results/ensembles/{ensemble}/init/seed{seed}.nc", ensemble=wildcards.ensemble, seed=seeds)


rule init_packing:
    """Random sequential addition start configuration for one (ensemble, seed)."""
    output:
        "results/ensembles/{ensemble}/init/seed{seed}.nc",
    params:
        n=lambda w: ENSEMBLES[w.ensemble]["N"],
        d=lambda w: ENSEMBLES[w.ensemble]["d"],
        phi=lambda w: ENSEMBLES[w.ensemble]["init_phi"],
        distribution=lambda w: json.dumps(ENSEMBLES[w.ensemble]["distribution"]),
    log:
        "results/logs/init_packing/{ensemble}_seed{seed}.log",
    shell:
        "hardpack init --n {params.n} --d {params.d} --phi {params.phi}"
        " --distribution '{params.distribution}' --seed {wildcards.seed}"
        " --attr ensemble={wildcards.ensemble} --out {output} 2> {log}"


rule init_summary:
    """One Dataset over the seeds of an ensemble, indexed by seed."""
    input:
        init_files,
    output:
        "results/ensembles/{ensemble}/init_summary.nc",
    log:
        "results/logs/init_summary/{ensemble}.log",
    shell:
        "hardpack combine {input} --index seed --variable init_phi"
        " --attr ensemble={wildcards.ensemble} --out {output} 2> {log}"


rule fig_size_distributions:
    """Sampled radii of every ensemble against the analytic size distribution."""
    input:
        expand("results/ensembles/{ensemble}/init_summary.nc", ensemble=ENSEMBLES),
    output:
        pdf="results/figures/size_distributions.pdf",
        png=report("results/figures/size_distributions.png", caption="../report/size_distributions.rst", category="1 generation"),
    params:
        distributions={name: ens["distribution"] for name, ens in ENSEMBLES.items()},
    log:
        "results/logs/figures/size_distributions.log",
    script:
        "../scripts/plot_size_distributions.py"


FIGURES.append("results/figures/size_distributions.pdf")
