# SLP studies (Torquato & Jiao 2010): the summaries that judge packings by their verdicts (order
# map, diluted MRJ) and the figures of Tables I, II and Fig. 6. The SLP runs themselves are the
# generic jobs of packings.smk (studies slp_mrj, slp_densest, slp_order_map, slp_diluted).


rule slp_order_map_summary:
    """phi, translational order T, jamming verdict and settings of every order-map packing."""
    input:
        packings=order_map_files("slp"),
        verdicts=order_map_files("verdict"),
    output:
        summary("slp_order_map/order_map"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("slp_order_map_summary"),
        runtime=job_runtime("slp_order_map_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/slp_order_map_summary.log",
    benchmark:
        "results/benchmarks/slp_order_map_summary.tsv"
    script:
        "../scripts/slp_order_map.py"


rule slp_diluted_summary:
    """phi, phi without rattlers, backbone Z, verdicts and T of every diluted-MRJ round, over (seed, round)."""
    input:
        packings=lambda w: diluted_files(w.name, "slp"),
        verdicts=lambda w: diluted_files(w.name, "verdict"),
    output:
        "results/slp_diluted/{name}/diluted_summary.nc",
    threads: 1
    resources:
        mem_mb=job_mem_mb("slp_diluted_summary"),
        runtime=job_runtime("slp_diluted_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/slp_diluted_summary/{name}.log",
    benchmark:
        "results/benchmarks/slp_diluted_summary/{name}.tsv"
    script:
        "../scripts/slp_diluted_summary.py"


rule fig_slp_densest:
    """Table II: SLP (and LS, where the config runs them) densities from N = 3^d starts against the densest known packings."""
    input:
        slp=summary("slp_densest/slp"),
        ls=[summary("ls_densest/jammed")] if LS_DENSEST else [],
    output:
        pdf="results/figures/slp_densest.pdf",
        png=report("results/figures/slp_densest.png", caption="../report/slp_densest.rst", category="6 SLP"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_slp_densest"),
        runtime=job_runtime("fig_slp_densest"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_slp_densest.log",
    benchmark:
        "results/benchmarks/fig_slp_densest.tsv"
    script:
        "../scripts/plot_slp_densest.py"


rule fig_slp_vs_ls:
    """Table I: SLP and LS jamming densities of the same ensembles, beside the published values;
    the SLP-only systems alone."""
    input:
        slp=[summary(f"slp_mrj/{name}/slp") for name in SYSTEMS["slp_mrj"]],
        ls=[summary(f"ls/{name}/jammed") for name in SYSTEMS["slp_mrj"] if name in ENSEMBLES],
    output:
        pdf="results/figures/slp_vs_ls.pdf",
        png=report("results/figures/slp_vs_ls.png", caption="../report/slp_vs_ls.rst", category="6 SLP"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_slp_vs_ls"),
        runtime=job_runtime("fig_slp_vs_ls"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_slp_vs_ls.log",
    benchmark:
        "results/benchmarks/fig_slp_vs_ls.tsv"
    script:
        "../scripts/plot_slp_vs_ls.py"


rule fig_slp_order_map:
    """Fig. 6: translational order T against phi of the SLP order-map and diluted-MRJ packings."""
    input:
        order_map=[summary("slp_order_map/order_map")] if SLP_ORDER else [],
        diluted=[summary(f"slp_diluted/{name}/diluted") for name in SYSTEMS["slp_diluted"]],
    output:
        pdf="results/figures/slp_order_map.pdf",
        png=report("results/figures/slp_order_map.png", caption="../report/slp_order_map.rst", category="6 SLP"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_slp_order_map"),
        runtime=job_runtime("fig_slp_order_map"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_slp_order_map.log",
    benchmark:
        "results/benchmarks/fig_slp_order_map.tsv"
    script:
        "../scripts/plot_slp_order_map.py"
