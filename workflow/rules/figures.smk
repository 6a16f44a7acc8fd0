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


rule fig_slp_vs_ls:
    """Table I: SLP and LS jamming densities of the same ensembles, beside the published values."""
    input:
        slp=expand("results/ensembles/{ensemble}/slp_summary.nc", ensemble=SLP_MRJ["ensembles"]) if SLP_MRJ else [],
        ls=expand("results/ensembles/{ensemble}/jammed_summary.nc", ensemble=SLP_MRJ["ensembles"]) if SLP_MRJ else [],
    output:
        pdf="results/figures/slp_vs_ls.pdf",
        png="results/figures/slp_vs_ls.png",
    log:
        "results/logs/figures/slp_vs_ls.log",
    script:
        "../scripts/plot_slp_vs_ls.py"


rule fig_bcmd_fcc:
    """BCMD free energy of FCC at melting and in the jamming limit vs N, with the published values."""
    input:
        expand("results/freeenergy/{state}_summary.nc", state=["melting", "jamming"]),
    output:
        pdf="results/figures/bcmd_fcc.pdf",
        png="results/figures/bcmd_fcc.png",
    log:
        "results/logs/figures/bcmd_fcc.log",
    script:
        "../scripts/plot_bcmd_fcc.py"


STRUCTURE_FILES = [f"results/ensembles/{e}/structure/seed{s}.nc" for e in ENSEMBLES for s in ENSEMBLES[e]["seeds"]]


rule fig_structure:
    """Structure figures of the LS packings: g2 near contact (split second peak), log-log Z(l), S(k) at small k."""
    input:
        STRUCTURE_FILES,
    output:
        pdf="results/figures/structure_{kind}.pdf",
        png="results/figures/structure_{kind}.png",
    wildcard_constraints:
        kind="g2|zl|sk",
    params:
        kind=lambda w: w.kind,
    log:
        "results/logs/figures/structure_{kind}.log",
    script:
        "../scripts/plot_structure.py"
