# Figures of the LS studies (Donev 2006): the ensembles' size distributions, phi_J and Z vs
# dimension, the growth-rate scan (Fig. 1.3) and the structure of the jammed packings (ch. 9-10).


rule fig_size_distributions:
    """Sampled radii of every ensemble against the analytic size distribution."""
    input:
        [summary(f"ls/{name}/init") for name in SYSTEMS["ls"]],
    output:
        pdf="results/figures/size_distributions.pdf",
        png=report("results/figures/size_distributions.png", caption="../report/size_distributions.rst", category="1 generation"),
    params:
        distributions={name: ens["distribution"] for name, ens in ENSEMBLES.items()},
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_size_distributions.log",
    benchmark:
        "results/benchmarks/fig_size_distributions.tsv"
    script:
        "../scripts/plot_size_distributions.py"


rule fig_jamming_vs_d:
    """phi_J and the contact number after rattlers of the monodisperse LS ensembles vs dimension."""
    input:
        jammed=[summary(f"ls/{name}/jammed") for name in monodisperse_ensembles()],
        verdicts=[summary(f"ls/{name}/verdict") for name in monodisperse_ensembles()],
    output:
        pdf="results/figures/jamming_vs_d.pdf",
        png=report("results/figures/jamming_vs_d.png", caption="../report/jamming_vs_d.rst", category="2 jamming"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_jamming_vs_d.log",
    benchmark:
        "results/benchmarks/fig_jamming_vs_d.tsv"
    script:
        "../scripts/plot_jamming_vs_d.py"


rule fig_rates:
    """Fig. 1.3 of Donev: phi_J estimate phi / (1 - d/Z) vs phi for each Gamma (kind=phij), or the
    reduced pressure Z vs phi against Carnahan-Starling and the free-volume law (kind=eos)."""
    input:
        rate_timeseries(),
    output:
        pdf="results/figures/ls_rates_{kind}.pdf",
        png=report("results/figures/ls_rates_{kind}.png", caption="../report/ls_rates.rst", category="1 generation"),
    wildcard_constraints:
        kind="phij|eos",
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_rates/{kind}.log",
    benchmark:
        "results/benchmarks/fig_rates/{kind}.tsv"
    script:
        "../scripts/plot_rates.py"


rule fig_structure:
    """Structure figures of the LS packings: g2 near contact (split second peak), log-log Z(l), S(k) at small k, channel-size histograms."""
    input:
        structure_files(),
    output:
        pdf="results/figures/structure_{kind}.pdf",
        png=report("results/figures/structure_{kind}.png", caption="../report/structure.rst", category="5 structure"),
    wildcard_constraints:
        kind="g2|zl|sk|channels",
    params:
        kind=lambda w: w.kind,
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_structure/{kind}.log",
    benchmark:
        "results/benchmarks/fig_structure/{kind}.tsv"
    script:
        "../scripts/plot_structure.py"
