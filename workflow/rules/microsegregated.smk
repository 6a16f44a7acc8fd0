# Micro-segregated binary disk packings (Donev 2006, sec. 13.5, Figs. 13.13-13.17): level-cut
# Matérn labels of one ensemble per (R, nu) plus the uncorrelated reference ("random"), each
# label realisation put on a triangular crystal whose B disks grow to kappa at constant reduced
# pressure before an LS compression to jamming; phi_J against the labels' s_c (Fig. 13.16).
#   results/microseg/labels/{ensemble}.nc            labels and window entropies (s_c)
#   results/microseg/{ensemble}/r{realisation}.nc     jammed packing (phi_J, s_c in its attributes)
#   results/microseg/{ensemble}/growth_r{realisation}.nc   the growth at constant pressure (Fig. 13.14)
#   results/microseg/phij_sc_summary.nc               phi_J and s_c per ensemble, the exponential fit s_c(phi_J)
#   results/figures/microsegregated.pdf               s_c vs phi_J with the fit (Fig. 13.16)
#   results/figures/microsegregated_maps.pdf          phi_J(R, nu) and s_c(R, nu) on the config's grid (Fig. 13.17)


rule microseg_labels:
    """Level-cut Matérn labels of one ensemble and their window entropies (Donev 2006, Fig. 13.15)."""
    output:
        "results/microseg/labels/{ensemble}.nc",
    params:
        R=lambda w: MICROSEG_ENSEMBLES[w.ensemble][0],
        nu=lambda w: MICROSEG_ENSEMBLES[w.ensemble][1],
        shape=" ".join(str(s) for s in MICROSEG["shape"]) if MICROSEG else None,
        window=" ".join(str(s) for s in MICROSEG["window"]) if MICROSEG else None,
        fraction=MICROSEG["fraction_a"] if MICROSEG else None,
        fields=MICROSEG["label_realisations"] if MICROSEG else None,
        seed=MICROSEG["seed"] if MICROSEG else None,
    wildcard_constraints:
        ensemble=one_of(MICROSEG_ENSEMBLES),
    threads: 1
    resources:
        mem_mb=job_mem_mb("microseg_labels"),
        runtime=job_runtime("microseg_labels"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/microseg_labels/{ensemble}.log",
    benchmark:
        "results/benchmarks/microseg_labels/{ensemble}.tsv"
    shell:
        "hardpack glass-labels --shape {params.shape} --R {params.R} --nu {params.nu} --fraction-a {params.fraction}"
        " --seed {params.seed} --realisations {params.fields} --window {params.window} --out {output} > {log} 2>&1"


rule microseg_packing:
    """Labelled crystal at p, B growth to kappa at constant p, LS compression to jamming (Donev 2006, sec. 13.5)."""
    input:
        "results/microseg/labels/{ensemble}.nc",
    output:
        packing="results/microseg/{ensemble}/r{realisation}.nc",
        growth="results/microseg/{ensemble}/growth_r{realisation}.nc",
    params:
        kappa=MICROSEG["kappa"] if MICROSEG else None,
        pressure=MICROSEG["pressure"] if MICROSEG else None,
        rate=MICROSEG["growth_rate"] if MICROSEG else None,
        crate=MICROSEG["compress_rate"] if MICROSEG else None,
        pmax=MICROSEG["max_pressure"] if MICROSEG else None,
        step=MICROSEG["cell_step"] if MICROSEG else None,
        seed=lambda w: MICROSEG["seed"] + int(w.realisation),
    wildcard_constraints:
        ensemble=one_of(MICROSEG_ENSEMBLES),
        realisation=r"\d+",
    threads: 1
    resources:
        mem_mb=job_mem_mb("microseg_packing"),
        runtime=job_runtime("microseg_packing"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/microseg_packing/{ensemble}/r{realisation}.log",
    benchmark:
        "results/benchmarks/microseg_packing/{ensemble}/r{realisation}.tsv"
    shell:
        "hardpack glass-microsegregated --labels {input} --realisation {wildcards.realisation}"
        " --ensemble {wildcards.ensemble} --kappa {params.kappa} --pressure {params.pressure}"
        " --growth-rate {params.rate} --compress-rate {params.crate} --max-pressure {params.pmax}"
        " --cell-step {params.step} --seed {params.seed} --out {output.packing}"
        " --growth-timeseries {output.growth} > {log} 2>&1"


rule microseg_summary:
    """phi_J and s_c of every label ensemble (Donev 2006, Figs. 13.16-13.17)."""
    input:
        microseg_packings(),
    output:
        summary("microseg/phij_sc"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("microseg_summary"),
        runtime=job_runtime("microseg_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/microseg_summary/summary.log",
    benchmark:
        "results/benchmarks/microseg_summary/summary.tsv"
    shell:
        "hardpack glass-microsegregated-summary {input} --out {output} > {log} 2>&1"


rule fig_microsegregated:
    """s_c vs phi_J of the micro-segregated packings with the exponential fit (after Donev 2006, Fig. 13.16)."""
    input:
        summary("microseg/phij_sc"),
    output:
        pdf="results/figures/microsegregated.pdf",
        png=report("results/figures/microsegregated.png", caption="../report/microsegregated.rst",
                   category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_microsegregated"),
        runtime=job_runtime("fig_microsegregated"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_microsegregated.log",
    benchmark:
        "results/benchmarks/fig_microsegregated.tsv"
    script:
        "../scripts/plot_microsegregated.py"


rule fig_microsegregated_maps:
    """phi_J(R, nu) and s_c(R, nu) over the config's grid of Matérn parameters (after Donev 2006, Fig. 13.17)."""
    input:
        summary("microseg/phij_sc"),
    output:
        pdf="results/figures/microsegregated_maps.pdf",
        png=report("results/figures/microsegregated_maps.png", caption="../report/microsegregated_maps.rst",
                   category="5 glasses"),
    params:
        R=MICROSEG["R"] if MICROSEG else None,
        nu=MICROSEG["nu"] if MICROSEG else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_microsegregated_maps"),
        runtime=job_runtime("fig_microsegregated_maps"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_microsegregated_maps.log",
    benchmark:
        "results/benchmarks/fig_microsegregated_maps.tsv"
    script:
        "../scripts/plot_microsegregated_maps.py"
