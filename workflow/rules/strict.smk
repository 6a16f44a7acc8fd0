# Strictly jammed LS packings (Donev 2006, Sec. 4.7.2.3): monodisperse packings grown in a
# deforming periodic cell by the generic init / compress / verify / combine jobs (packings.smk,
# study strict_ls), and their picture after Fig. 4.15.


rule fig_strict_ls:
    """The first strictly jammed disk packing of the deforming-cell LS study, with its contact
    forces (after Donev 2006, Fig. 4.15)."""
    input:
        packing=lambda w: seed_files("strict_ls", "d2", "jammed")[0],
        verdict=lambda w: seed_files("strict_ls", "d2", "verdict")[0],
    output:
        pdf="results/figures/strict_ls_disks.pdf",
        png=report("results/figures/strict_ls_disks.png", caption="../report/strict_ls.rst", category="2 jamming"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_strict_ls"),
        runtime=job_runtime("fig_strict_ls"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_strict_ls.log",
    benchmark:
        "results/benchmarks/fig_strict_ls.tsv"
    script:
        "../scripts/plot_strict_ls.py"
