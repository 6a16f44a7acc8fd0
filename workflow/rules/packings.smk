# The packing studies' generic jobs, one rule each for every study (SYSTEMS in common.smk):
# start configurations, the generators (LS compression, SLP, SLP dilution), jamming verdicts,
# structure, and the summaries over seeds and systems (hardpack combine).


rule init:
    """Random sequential addition start configuration of one system and seed (spheres, or ellipsoids
    with the system's semiaxes)."""
    output:
        "results/{study}/{name}/init/seed{seed}.nc",
    params:
        n=lambda w: system(w)["N"],
        d=lambda w: system(w)["d"],
        phi=lambda w: system(w)["init_phi"],
        distribution=lambda w: json.dumps(system(w)["distribution"]),
        attrs=lambda w: attr_options(system(w)["attrs"]),
        shape=init_shape,
    wildcard_constraints:
        study="ls|slp_mrj|slp_densest|slp_order_map|ellipsoids|strict_ls|ls_densest",
    threads: 1
    resources:
        mem_mb=job_mem_mb("init"),
        runtime=job_runtime("init"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/init/{study}/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/init/{study}/{name}/seed{seed}.tsv"
    shell:
        "hardpack init --n {params.n} --d {params.d} --phi {params.phi}"
        " --distribution '{params.distribution}' {params.shape} --seed {wildcards.seed} {params.attrs}"
        " --out {output} > {log} 2>&1"


rule compress:
    """LS compression of one start configuration to the system's reduced pressure: the LS ensembles'
    two-stage protocol (with contact forces), one growth rate of the rate scan, the ellipsoid
    study's two-stage protocol, spheres or M&M-shaped ellipsoids in a spherical container, or spheres
    in a deforming cell."""
    input:
        start_packing,
    output:
        packing="results/{study}/{name}/jammed/seed{seed}.nc",
        timeseries="results/{study}/{name}/timeseries/seed{seed}.nc",
    params:
        options=lambda w: system(w)["compress"],
        checkpoint=checkpoint_option,
    wildcard_constraints:
        study="ls|ls_rates|ellipsoids|containers|ellipsoid_containers|strict_ls|ls_densest",
    threads: 1
    resources:
        mem_mb=job_mem_mb("compress"),
        runtime=job_runtime("compress"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/compress/{study}/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/compress/{study}/{name}/seed{seed}.tsv"
    shell:
        "hardpack compress --init {input} --out {output.packing} --timeseries {output.timeseries}"
        " {params.options} --seed {wildcards.seed} {params.checkpoint} > {log} 2>&1"


rule slp:
    """SLP (Torquato & Jiao 2010) with a deforming cell from one start, with the system's settings:
    Table I (MRJ), Table II (densest) or one order-map setting."""
    input:
        start_packing,
    output:
        packing="results/{study}/{name}/slp/seed{seed}.nc",
        history="results/{study}/{name}/history/seed{seed}.nc",
    params:
        flags=lambda w: system(w)["slp"],
        attrs=lambda w: attr_options(system(w)["attrs"]),
        checkpoint=checkpoint_beside,
    wildcard_constraints:
        study="slp_mrj|slp_densest|slp_order_map",
    threads: 1
    resources:
        mem_mb=job_mem_mb("slp"),
        runtime=job_runtime("slp"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/slp/{study}/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/slp/{study}/{name}/seed{seed}.tsv"
    shell:
        "hardpack slp --init {input} --out {output.packing} --history {output.history} {params.flags}"
        " {params.attrs} --checkpoint {params.checkpoint} > {log} 2>&1"


rule slp_dilute:
    """Torquato & Jiao 2010, Sec. VI: remove a fraction of the spheres of one SLP MRJ packing at
    random, re-jam by SLP (the Table I settings), repeat; one packing per round."""
    input:
        start_packing,
    output:
        expand("results/{{study}}/{{name}}/slp/seed{{seed}}/round{r}.nc",
               r=range(1, SLP_DILUTED["rounds"] + 1) if SLP_DILUTED else []),
    params:
        flags=lambda w: system(w)["slp"],
        options=lambda w: system(w)["dilute"],
        out_dir=lambda w, output: os.path.dirname(output[0]),
        checkpoint=checkpoint_beside,
    wildcard_constraints:
        study="slp_diluted",
    threads: 1
    resources:
        mem_mb=job_mem_mb("slp_dilute"),
        runtime=job_runtime("slp_dilute"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/slp_dilute/{study}/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/slp_dilute/{study}/{name}/seed{seed}.tsv"
    shell:
        "hardpack slp-dilute --init {input} --out-dir {params.out_dir} {params.options}"
        " --seed {wildcards.seed} {params.flags} --checkpoint {params.checkpoint} > {log} 2>&1"


rule verify:
    """LP jamming tests of one packing by sequential random loading (Donev Algorithm 14), LS and SLP
    alike. Meant for finite-rate LS packings, whose near-contacts at gaps ~1e-6..1e-5 block the few
    floppy modes the linearised ideal test of the delta-contact network would report; SLP stops
    when no LP step gains density, which can leave near contacts at gaps 1e-6..1e-4 D too
    (measured: a 6D N = 250 SLP packing with 18 such near contacts is 'not strict' by the ideal
    test, moving 1.5 D linearly, and strictly jammed by the sequential one)."""
    input:
        packed_file,
    output:
        "results/{study}/{name}/verdict/{sample}.nc",
    params:
        seed=sample_seed,
        checkpoint=checkpoint_beside,
    wildcard_constraints:
        study="|".join(PACKED),
        sample=r"seed\d+(/round\d+)?",
    threads: verify_threads
    resources:
        mem_mb=job_mem_mb("verify"),
        runtime=job_runtime("verify"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/verify/{study}/{name}/{sample}.log",
    benchmark:
        "results/benchmarks/verify/{study}/{name}/{sample}.tsv"
    shell:
        "hardpack verify {input} --out {output} --seed {params.seed} --method sequential"
        " --workers {threads} --checkpoint {params.checkpoint} > {log} 2>&1"


rule structure:
    """Structure analysis of one packing (g2 near contact and Z(l), S(k), order metrics), rattlers
    from its jamming verdict."""
    input:
        packing=lambda w: f"results/{w.study}/{w.name}/{PACKED[w.study]}/seed{w.seed}.nc",
        verdict="results/{study}/{name}/verdict/seed{seed}.nc",
    output:
        "results/{study}/{name}/structure/seed{seed}.nc",
    params:
        attrs=lambda w: attr_options(system(w)["attrs"]),
    wildcard_constraints:
        study="ls",
    threads: 1
    resources:
        mem_mb=job_mem_mb("structure"),
        runtime=job_runtime("structure"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/structure/{study}/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/structure/{study}/{name}/seed{seed}.tsv"
    shell:
        "hardpack structure {input.packing} --jamming {input.verdict} {params.attrs} --out {output} > {log} 2>&1"


rule combine:
    """One Dataset over the per-seed files of a system or a study (COMBINED in common.smk),
    indexed by their attributes (seed, d, phi, ...)."""
    input:
        lambda w: COMBINED[w.key]["inputs"],
    output:
        "results/{key}_summary.nc",
    params:
        options=lambda w: COMBINED[w.key]["options"],
    wildcard_constraints:
        key=one_of(COMBINED),
    threads: 1
    resources:
        mem_mb=job_mem_mb("combine"),
        runtime=job_runtime("combine"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/combine/{key}.log",
    benchmark:
        "results/benchmarks/combine/{key}.tsv"
    shell:
        "hardpack combine {input} {params.options} --out {output} > {log} 2>&1"
