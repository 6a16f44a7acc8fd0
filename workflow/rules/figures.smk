# Figures: one rule per figure, results/figures/<name>.pdf (+ .png).


rule fig_size_distributions:
    """Sampled radii of every ensemble against the analytic size distribution."""
    input:
        expand("results/ensembles/{ensemble}/init_summary.nc", ensemble=ENSEMBLES),
    output:
        pdf="results/figures/size_distributions.pdf",
        png="results/figures/size_distributions.png",
    params:
        distributions={name: ens["distribution"] for name, ens in ENSEMBLES.items()},
    log:
        "results/logs/figures/size_distributions.log",
    script:
        "../scripts/plot_size_distributions.py"


rule fig_slp_densest:
    """Table II: SLP densities from N = 3^d starts against the densest known packings."""
    input:
        "results/slp/densest_summary.nc",
    output:
        pdf="results/figures/slp_densest.pdf",
        png="results/figures/slp_densest.png",
    log:
        "results/logs/figures/slp_densest.log",
    script:
        "../scripts/plot_slp_densest.py"
