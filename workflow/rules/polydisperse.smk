# EOS and jamming density of polydisperse spheres vs their moment-matched bi- and tridisperse
# equivalents (Ogarko ch. 3). One job per (family, width, seed, system) jams the polydisperse system
# or one of its equivalents, all with the same protocol and N (a checkpoint lets a killed job
# resume: the slow runs take up to ~20 CPU min each); one job per (family, width) measures the
# fluid Z(phi) of the three against BMCSL. The same jobs with a slow final stage
# (study poly_crystallisation) look for the large-species crystallisation of the bidisperse
# equivalents (Ogarko 2014, sec. 3.1.3). Summaries, figures and validation rows follow.


rule poly_jam:
    """Two-stage LS compression of the polydisperse system or one of its bi- and tridisperse equivalents."""
    output:
        "results/poly_{protocol}/{family}_w{width}/{system}/seed{seed}.nc",
    params:
        checkpoint=checkpoint_beside,
        spec=poly_spec,
        n=lambda w: poly_protocol(w)["N"],
        init_phi=lambda w: poly_protocol(w)["init_phi"],
        growth_rate=lambda w: poly_protocol(w)["growth_rate"],
        switch_pressure=lambda w: poly_protocol(w)["switch_pressure"],
        final_growth_rate=lambda w: poly_protocol(w)["final_growth_rate"],
        max_pressure=lambda w: poly_protocol(w)["max_pressure"],
    wildcard_constraints:
        protocol="|".join(POLY_PROTOCOLS),
        family=POLY_FAMILY,
        width=POLY_WIDTH,
        system="|".join(POLY_SYSTEMS),
    threads: 1
    resources:
        mem_mb=job_mem_mb("poly_jam"),
        runtime=job_runtime("poly_jam"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/poly_jam/{protocol}/{family}_w{width}/{system}/seed{seed}.log",
    benchmark:
        "results/benchmarks/poly_jam/{protocol}/{family}_w{width}/{system}/seed{seed}.tsv"
    shell:
        "hardpack poly-jam --distribution '{params.spec}' --systems {wildcards.system} --seed {wildcards.seed}"
        " --n {params.n} --init-phi {params.init_phi} --growth-rate {params.growth_rate}"
        " --switch-pressure {params.switch_pressure} --final-growth-rate {params.final_growth_rate}"
        " --max-pressure {params.max_pressure} --out {output} --checkpoint {params.checkpoint} > {log} 2>&1"


rule poly_fluid:
    """Equilibrium Z(phi) of the distribution and its equivalents, against BMCSL."""
    output:
        "results/poly_fluid/{family}_w{width}/fluid.nc",
    params:
        spec=poly_spec,
        phi=" ".join(str(p) for p in POLY_FLUID.get("phi", [])),
        n=POLY_FLUID.get("N"),
        collisions=POLY_FLUID.get("collisions"),
        seed=POLY_FLUID.get("seed"),
    wildcard_constraints:
        family=POLY_FAMILY,
        width=POLY_WIDTH,
    threads: 1
    resources:
        mem_mb=job_mem_mb("poly_fluid"),
        runtime=job_runtime("poly_fluid"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/poly_fluid/{family}_w{width}.log",
    benchmark:
        "results/benchmarks/poly_fluid/{family}_w{width}.tsv"
    shell:
        "hardpack poly-fluid --distribution '{params.spec}' --systems poly bi tri --phi {params.phi}"
        " --n {params.n} --collisions {params.collisions} --seed {params.seed} --out {output} > {log} 2>&1"


rule poly_summary:
    """phi_J (and large-species crystallinity) over (width, system, seed) for one family, or all
    fluid cases in one Dataset (case, system, phi): EOS_SUMMARIES in common.smk."""
    input:
        lambda w: EOS_SUMMARIES[w.key]["inputs"],
    output:
        "results/{key}_summary.nc",
    params:
        kind=lambda w: EOS_SUMMARIES[w.key]["kind"],
    wildcard_constraints:
        key=one_of(EOS_SUMMARIES),
    threads: 1
    resources:
        mem_mb=job_mem_mb("poly_summary"),
        runtime=job_runtime("poly_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/poly_summary/{key}.log",
    benchmark:
        "results/benchmarks/poly_summary/{key}.tsv"
    shell:
        "hardpack poly-summary --kind {params.kind} {input} --out {output} > {log} 2>&1"


rule fig_phij_vs_omega:
    """phi_J vs omega (sigma) for poly / bi / tri with the published fits, and relative deviations."""
    input:
        [summary(f"poly_phij/{family}") for family in POLY_PROTOCOLS["phij"].get("widths", {})],
    output:
        pdf="results/figures/phij_vs_omega.pdf",
        png=report("results/figures/phij_vs_omega.png", caption="../report/polydisperse_phij.rst",
                   category="3 polydisperse"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_phij_vs_omega"),
        runtime=job_runtime("fig_phij_vs_omega"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_phij_vs_omega.log",
    benchmark:
        "results/benchmarks/fig_phij_vs_omega.tsv"
    script:
        "../scripts/plot_poly_phij.py"


rule fig_eos_vs_bmcsl:
    """Fluid Z vs phi against BMCSL (and Ogarko's Z_OL) for every distribution and its equivalents."""
    input:
        summary("poly_fluid/fluid"),
    output:
        pdf="results/figures/eos_vs_bmcsl.pdf",
        png=report("results/figures/eos_vs_bmcsl.png", caption="../report/polydisperse_eos.rst",
                   category="3 polydisperse"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_eos_vs_bmcsl"),
        runtime=job_runtime("fig_eos_vs_bmcsl"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_eos_vs_bmcsl.log",
    benchmark:
        "results/benchmarks/fig_eos_vs_bmcsl.tsv"
    script:
        "../scripts/plot_poly_eos.py"


rule fig_crystallisation:
    """Slow runs: phi_J and the large-species crystallinity vs omega (uniform size)."""
    input:
        summary("poly_crystallisation/uniform_size"),
    output:
        pdf="results/figures/crystallisation_vs_omega.pdf",
        png=report("results/figures/crystallisation_vs_omega.png",
                   caption="../report/polydisperse_crystallisation.rst", category="3 polydisperse"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_crystallisation"),
        runtime=job_runtime("fig_crystallisation"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_crystallisation.log",
    benchmark:
        "results/benchmarks/fig_crystallisation.tsv"
    script:
        "../scripts/plot_poly_crystallisation.py"
