# Configurational entropy of binary hard-disk glasses (Donev 2006, ch. 13; Donev, Stillinger &
# Torquato 2006): compressions of the 1:2 mixture of disks with diameter ratio 1.4 and of
# monodisperse disks at several growth rates in stages through the snapshot densities, the
# decompression of the triangular crystal, BCMD of the snapshots of the slowest compression in
# bounding cells, the EOS summaries with the fits of Eqs. 13.3-13.4, s_c - s_mix (Eq. 13.5) and the
# freezing point (Eq. 13.2). The micro-segregated packings of sec. 13.5 are in microsegregated.smk.



rule glass_init:
    """RSA start of a glass system at low density (the EOS integral starts there)."""
    output:
        "results/glass/{system}/init/seed{seed}.nc",
    params:
        spec=glass_distribution,
        n=GLASS["N"] if GLASS else None,
        phi=GLASS["init_phi"] if GLASS else None,
    wildcard_constraints:
        system=one_of(GLASS_SYSTEMS),
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_init"),
        runtime=job_runtime("glass_init"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_init/{system}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_init/{system}/seed{seed}.tsv"
    shell:
        "hardpack init --n {params.n} --d 2 --phi {params.phi} --distribution '{params.spec}'"
        " --seed {wildcards.seed} --out {output} > {log} 2>&1"


rule glass_compress:
    """One LS compression stage at growth rate {rate} from the previous stage (or the start) to phi{phi}, stopped early if Z reaches max_pressure; the packing is a snapshot."""
    input:
        glass_previous,
    output:
        packing="results/glass/{system}/g{rate}/phi{phi}/seed{seed}.nc",
        timeseries="results/glass/{system}/g{rate}/phi{phi}/ts_seed{seed}.nc",
    params:
        checkpoint=checkpoint_beside,
        max_pressure=GLASS["max_pressure"] if GLASS else None,
    wildcard_constraints:
        system=one_of(GLASS_SYSTEMS),
        rate=r"[0-9.e+-]+",
        phi=GLASS_PHI,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_compress"),
        runtime=job_runtime("glass_compress"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_compress/{system}/g{rate}/phi{phi}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_compress/{system}/g{rate}/phi{phi}/seed{seed}.tsv"
    shell:
        "hardpack compress --init {input} --growth-rate {wildcards.rate} --seed {wildcards.seed}"
        " --target-phi {wildcards.phi} --max-pressure {params.max_pressure} --out {output.packing}"
        " --timeseries {output.timeseries} --checkpoint {params.checkpoint} > {log} 2>&1"


rule glass_crystal:
    """Monodisperse triangular crystal of N disks at glass.mono.crystal_phi."""
    output:
        "results/glass/mono/crystal.nc",
    params:
        cells=lambda w: glass_crystal_cells(),
        phi=GLASS["mono"]["crystal_phi"] if GLASS else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_crystal"),
        runtime=job_runtime("glass_crystal"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_crystal/crystal.log",
    benchmark:
        "results/benchmarks/glass_crystal/crystal.tsv"
    shell:
        "hardpack glass-crystal --nx {params.cells[0]} --ny {params.cells[1]} --phi {params.phi}"
        " --out {output} > {log} 2>&1"


rule glass_decompress:
    """Slow decompression of the triangular crystal (growth rate -glass.mono.rate) to glass.mono.decompress_to."""
    input:
        "results/glass/mono/crystal.nc",
    output:
        packing="results/glass/mono/decompression/seed{seed}.nc",
        timeseries="results/glass/mono/decompression/ts_seed{seed}.nc",
    params:
        checkpoint=checkpoint_beside,
        rate=GLASS["mono"]["rate"] if GLASS else None,
        phi=GLASS["mono"]["decompress_to"] if GLASS else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_decompress"),
        runtime=job_runtime("glass_decompress"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_decompress/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_decompress/seed{seed}.tsv"
    shell:
        "hardpack compress --init {input} --growth-rate=-{params.rate} --seed {wildcards.seed}"
        " --target-phi {params.phi} --out {output.packing} --timeseries {output.timeseries}"
        " --checkpoint {params.checkpoint} > {log} 2>&1"


rule glass_crystal_bcmd:
    """BCMD free energy of the defect-free triangular crystal at {phi} (the glass.mono.crystal_phi
    crystal with its radii rescaled; Donev 2006, Fig. 13.2), with the glass snapshots' BCMD settings."""
    input:
        "results/glass/mono/crystal.nc",
    output:
        "results/glass/mono/crystal_bcmd/phi{phi}/seed{seed}.nc",
    params:
        b=GLASS["bcmd"] if GLASS else None,
        thermostat=glass_bcmd_thermostat,
    wildcard_constraints:
        phi=GLASS_PHI,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_crystal_bcmd"),
        runtime=job_runtime("glass_crystal_bcmd"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_crystal_bcmd/phi{phi}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_crystal_bcmd/phi{phi}/seed{seed}.tsv"
    shell:
        "hardpack bcmd {input} --out {output} --phi {wildcards.phi} --dmu-max {params.b[dmu_max]}"
        " --gamma0 {params.b[gamma0]} --theta {params.b[theta]} {params.thermostat} --seed {wildcards.seed}"
        " > {log} 2>&1"


rule glass_relaxation:
    """Pressure of the mixture's glass at fixed glass.relaxation.phi after compression at {rate}:
    NVE MD from the snapshot, Z per block from the first collision on (Donev 2006, Fig. 13.7)."""
    input:
        lambda w: glass_snapshot("binary", w.rate, GLASS["relaxation"]["phi"], w.seed),
    output:
        "results/glass/binary/relaxation/g{rate}/seed{seed}.nc",
    params:
        checkpoint=checkpoint_beside,
        collisions=lambda w: int(GLASS["relaxation"]["collisions_per_particle"] * GLASS["N"]),
        blocks=GLASS["relaxation"]["blocks"] if GLASS and GLASS.get("relaxation") else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_relaxation"),
        runtime=job_runtime("glass_relaxation"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_relaxation/g{rate}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_relaxation/g{rate}/seed{seed}.tsv"
    shell:
        "hardpack eos --init {input} --seed {wildcards.seed} --collisions {params.collisions}"
        " --blocks {params.blocks} --equilibration 0 --out {output} --checkpoint {params.checkpoint} > {log} 2>&1"


rule glass_soc:
    """SOC solid of the mixture (Donev 2006, sec. 13.3.1, Fig. 13.9): the slowest compression's snapshot at {phi} with every disk in a fixed cell of glass.soc.dmu radii, grown at glass.soc.rate to the pair pressure glass.soc.max_pressure."""
    input:
        glass_soc_snapshot,
    output:
        packing="results/glass/binary/soc/phi{phi}/seed{seed}.nc",
        timeseries="results/glass/binary/soc/phi{phi}/ts_seed{seed}.nc",
    params:
        checkpoint=checkpoint_beside,
        s=GLASS.get("soc") if GLASS else None,
    wildcard_constraints:
        phi=GLASS_PHI,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_soc"),
        runtime=job_runtime("glass_soc"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_soc/phi{phi}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_soc/phi{phi}/seed{seed}.tsv"
    shell:
        "hardpack glass-soc {input} --dmu {params.s[dmu]} --growth-rate {params.s[rate]}"
        " --max-pressure {params.s[max_pressure]} --seed {wildcards.seed} --out {output.packing}"
        " --timeseries {output.timeseries} --checkpoint {params.checkpoint} > {log} 2>&1"


rule glass_soc_relaxation:
    """The SOC solid at {phi} with its cells removed: NVE MD at its final phi for glass.soc.relax_collisions_per_particle collisions per disk, Z per block (Donev 2006, Fig. 13.9)."""
    input:
        "results/glass/binary/soc/phi{phi}/seed{seed}.nc",
    output:
        "results/glass/binary/soc/phi{phi}/relaxed_seed{seed}.nc",
    params:
        checkpoint=checkpoint_beside,
        collisions=lambda w: int(GLASS["soc"]["relax_collisions_per_particle"] * GLASS["N"]),
        blocks=GLASS["soc"]["blocks"] if GLASS and GLASS.get("soc") else None,
    wildcard_constraints:
        phi=GLASS_PHI,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_soc_relaxation"),
        runtime=job_runtime("glass_soc_relaxation"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_soc_relaxation/phi{phi}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_soc_relaxation/phi{phi}/seed{seed}.tsv"
    shell:
        "hardpack eos --init {input} --seed {wildcards.seed} --collisions {params.collisions}"
        " --blocks {params.blocks} --equilibration 0 --out {output} --checkpoint {params.checkpoint} > {log} 2>&1"


rule glass_soc_summary:
    """phi_J of the SOC solids in their cells and after relaxation without them, per phi_0 and seed (Donev 2006, Fig. 13.9)."""
    input:
        soc=lambda w: glass_soc_files("ts_"),
        relaxed=lambda w: glass_soc_files("relaxed_"),
    output:
        "results/glass/binary/soc_summary.nc",
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_soc_summary"),
        runtime=job_runtime("glass_soc_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_soc_summary.log",
    benchmark:
        "results/benchmarks/glass_soc_summary.tsv"
    shell:
        "hardpack glass-soc-summary --soc {input.soc} --relaxed {input.relaxed} --out {output} > {log} 2>&1"


rule glass_separated_crystal:
    """The fully phase-separated crystal of the mixture: a slab of small and a slab of large disks at glass.separated.phi (Donev 2006, sec. 13.2.2.1)."""
    output:
        "results/glass/separated/crystal.nc",
    params:
        s=GLASS.get("separated") if GLASS else None,
        kappa=GLASS["kappa"] if GLASS else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_separated_crystal"),
        runtime=job_runtime("glass_separated_crystal"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_separated_crystal/crystal.log",
    benchmark:
        "results/benchmarks/glass_separated_crystal/crystal.tsv"
    shell:
        "hardpack glass-separated-crystal --columns {params.s[columns][0]} {params.s[columns][1]}"
        " --rows {params.s[rows][0]} {params.s[rows][1]} --kappa {params.kappa} --phi {params.s[phi]}"
        " --out {output} > {log} 2>&1"


rule glass_separated_decompress:
    """Decompression of the phase-separated crystal at growth rate -{rate} to glass.separated.phi_end (Donev 2006, Fig. 13.5)."""
    input:
        "results/glass/separated/crystal.nc",
    output:
        packing="results/glass/separated/g{rate}/seed{seed}.nc",
        timeseries="results/glass/separated/g{rate}/ts_seed{seed}.nc",
    params:
        checkpoint=checkpoint_beside,
        phi=GLASS["separated"]["phi_end"] if GLASS and GLASS.get("separated") else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_separated_decompress"),
        runtime=job_runtime("glass_separated_decompress"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_separated_decompress/g{rate}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_separated_decompress/g{rate}/seed{seed}.tsv"
    shell:
        "hardpack compress --init {input} --growth-rate=-{wildcards.rate} --seed {wildcards.seed}"
        " --target-phi {params.phi} --out {output.packing} --timeseries {output.timeseries}"
        " --checkpoint {params.checkpoint} > {log} 2>&1"


rule glass_eos:
    """Binned EOS of a glass system, its EOS integral from the ideal gas and the fits of Eqs. 13.3-13.4."""
    input:
        lambda w: glass_timeseries(w.system),
    output:
        "results/glass/{system}/eos_summary.nc",
    params:
        kappa=lambda w: GLASS_SYSTEMS[w.system]["kappa"],
        x=lambda w: GLASS_SYSTEMS[w.system]["x"],
        e=GLASS["eos"] if GLASS else None,
        continues=glass_continues_option,
    wildcard_constraints:
        system=one_of(GLASS_SYSTEMS),
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_eos"),
        runtime=job_runtime("glass_eos"),
    group:
        "analyses"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_eos/{system}.log",
    benchmark:
        "results/benchmarks/glass_eos/{system}.tsv"
    shell:
        "hardpack glass-eos {input} --system {wildcards.system} --kappa {params.kappa} --x-large {params.x}"
        " --bin-width {params.e[bin_width]} --liquid-range {params.e[liquid_range][0]} {params.e[liquid_range][1]}"
        " --glass-range {params.e[glass_range][0]} {params.e[glass_range][1]} {params.continues}"
        " --out {output} > {log} 2>&1"


rule glass_bcmd:
    """BCMD free energy of a glass snapshot in bounding cells (Delta mu from glass.bcmd.dmu_max to the disjoint point), radii shrunk by (1 - glass.bcmd.delta) so that the cells become disjoint at Delta mu ~ delta (an MD snapshot has pairs within ~1e-10 of contact, and the BCMD cost grows as 1 / Delta mu_min)."""
    input:
        "results/glass/{system}/g{rate}/phi{phi}/seed{seed}.nc",
    output:
        "results/glass/{system}/bcmd/g{rate}/phi{phi}/seed{seed}.nc",
    params:
        b=GLASS["bcmd"] if GLASS else None,
        thermostat=glass_bcmd_thermostat,
    wildcard_constraints:
        system="binary|mono",
        phi=GLASS_PHI,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_bcmd"),
        runtime=job_runtime("glass_bcmd"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_bcmd/{system}/g{rate}/phi{phi}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_bcmd/{system}/g{rate}/phi{phi}/seed{seed}.tsv"
    shell:
        "hardpack bcmd {input} --out {output} --delta {params.b[delta]} --dmu-max {params.b[dmu_max]} --gamma0 {params.b[gamma0]}"
        " --theta {params.b[theta]} {params.thermostat} --seed {wildcards.seed} > {log} 2>&1"


rule glass_entropy:
    """s_c - s_mix of the SOC glasses of a system (Donev 2006, Eq. 13.5, Fig. 13.12)."""
    input:
        eos="results/glass/{system}/eos_summary.nc",
        bcmd=lambda w: glass_bcmd_files(w.system),
    output:
        "results/glass/{system}/entropy_summary.nc",
    wildcard_constraints:
        system="binary|mono",
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_entropy"),
        runtime=job_runtime("glass_entropy"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_entropy/{system}.log",
    benchmark:
        "results/benchmarks/glass_entropy/{system}.tsv"
    shell:
        "hardpack glass-entropy --eos {input.eos} {input.bcmd} --out {output} > {log} 2>&1"


rule glass_freezing:
    """Freezing of the mixture against the pure large-disk crystal (Donev 2006, Eq. 13.2)."""
    input:
        mono="results/glass/mono/eos_summary.nc",
        mixture="results/glass/binary/eos_summary.nc",
        plus="results/glass/binary_xm/eos_summary.nc",
        minus="results/glass/binary_xp/eos_summary.nc",
    output:
        "results/glass/freezing_summary.nc",
    params:
        kappa=GLASS["kappa"] if GLASS else None,
        x=GLASS["x_large"] if GLASS else None,
        dx=GLASS["composition"]["dx"] if GLASS else None,
        join=GLASS["eos"]["phi_join"] if GLASS else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_freezing"),
        runtime=job_runtime("glass_freezing"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_freezing/freezing.log",
    benchmark:
        "results/benchmarks/glass_freezing/freezing.tsv"
    shell:
        "hardpack glass-freezing --mono {input.mono} --mixture {input.mixture} --plus {input.plus}"
        " --minus {input.minus} --dx {params.dx} --kappa {params.kappa} --x-large {params.x}"
        " --phi-join {params.join} --out {output} > {log} 2>&1"


rule glass_relaxed:
    """A fast glass of the mixture relaxed and recompressed (Donev 2006, Fig. 13.8): LS at growth rate {rate} to glass.relaxed.max_pressure, MD at fixed phi for glass.relaxed.relax_collisions collisions per particle, LS at glass.relaxed.rate to the same pressure."""
    input:
        "results/glass/binary/init/seed{seed}.nc",
    output:
        fast="results/glass/binary/relaxed/g{rate}/fast_seed{seed}.nc",
        relaxed="results/glass/binary/relaxed/g{rate}/relaxed_seed{seed}.nc",
        jammed="results/glass/binary/relaxed/g{rate}/seed{seed}.nc",
    params:
        r=GLASS.get("relaxed") if GLASS else None,
        collisions=lambda w: math.ceil(GLASS["N"] * GLASS["relaxed"]["relax_collisions"]),
    wildcard_constraints:
        rate=r"[0-9.e+-]+",
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_relaxed"),
        runtime=job_runtime("glass_relaxed"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_relaxed/g{rate}/seed{seed}.log",
    benchmark:
        "results/benchmarks/glass_relaxed/g{rate}/seed{seed}.tsv"
    shell:
        "(hardpack compress --init {input} --growth-rate {wildcards.rate} --seed {wildcards.seed}"
        " --max-pressure {params.r[max_pressure]} --out {output.fast}"
        " && hardpack compress --init {output.fast} --growth-rate 0 --seed {wildcards.seed}"
        " --max-collisions {params.collisions} --max-pressure none --out {output.relaxed}"
        " && hardpack compress --init {output.relaxed} --growth-rate {params.r[rate]} --seed {wildcards.seed}"
        " --max-pressure {params.r[max_pressure]} --out {output.jammed}) > {log} 2>&1"


rule glass_relaxed_summary:
    """phi_J of the fast glasses before and after relaxation, over rates and seeds (Donev 2006, Fig. 13.8)."""
    input:
        fast=lambda w: glass_relaxed_files("fast_"),
        jammed=lambda w: glass_relaxed_files(""),
    output:
        "results/glass/binary/relaxed_summary.nc",
    params:
        collisions=GLASS["relaxed"]["relax_collisions"] if GLASS and GLASS.get("relaxed") else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("glass_relaxed_summary"),
        runtime=job_runtime("glass_relaxed_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/glass_relaxed_summary.log",
    benchmark:
        "results/benchmarks/glass_relaxed_summary.tsv"
    shell:
        "hardpack glass-relaxed --fast {input.fast} --jammed {input.jammed}"
        " --relax-collisions {params.collisions} --out {output} > {log} 2>&1"


rule fig_glass_eos:
    """phi~_J(phi) of the compressions and decompression (mono, binary) with the published and fitted Eq. 13.3, 13.4 (Donev 2006, Figs. 13.1, 13.6)."""
    input:
        binary="results/glass/binary/eos_summary.nc",
        mono="results/glass/mono/eos_summary.nc",
    output:
        pdf="results/figures/glass_eos.pdf",
        png=report("results/figures/glass_eos.png", caption="../report/glass_eos.rst", category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_eos"),
        runtime=job_runtime("fig_glass_eos"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_eos.log",
    benchmark:
        "results/benchmarks/fig_glass_eos.tsv"
    script:
        "../scripts/plot_glass_eos.py"


rule fig_glass_entropy:
    """Excess free energies of liquid and SOC glasses and s_c - s_mix vs phi (Donev 2006, Figs. 13.11-13.12)."""
    input:
        binary="results/glass/binary/entropy_summary.nc",
        mono="results/glass/mono/entropy_summary.nc",
    output:
        pdf="results/figures/glass_entropy.pdf",
        png=report("results/figures/glass_entropy.png", caption="../report/glass_entropy.rst", category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_entropy"),
        runtime=job_runtime("fig_glass_entropy"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_entropy.log",
    benchmark:
        "results/benchmarks/fig_glass_entropy.tsv"
    script:
        "../scripts/plot_glass_entropy.py"


rule fig_glass_crystal:
    """Free energy of monodisperse disks by EOS integration and by BCMD of the defect-free crystal (Donev 2006, Fig. 13.2)."""
    input:
        eos="results/glass/mono/eos_summary.nc",
        crystal="results/glass/mono/crystal_bcmd_summary.nc",
    output:
        pdf="results/figures/glass_crystal.pdf",
        png=report("results/figures/glass_crystal.png", caption="../report/glass_crystal.rst", category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_crystal"),
        runtime=job_runtime("fig_glass_crystal"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_crystal.log",
    benchmark:
        "results/benchmarks/fig_glass_crystal.tsv"
    script:
        "../scripts/plot_glass_crystal.py"


rule fig_glass_cell_pressure:
    """Cell-wall pressure of the SOC glasses vs cell size during BCMD (Donev 2006, Fig. 13.10)."""
    input:
        binary=lambda w: glass_bcmd_files("binary"),
        mono=lambda w: glass_bcmd_files("mono"),
    output:
        pdf="results/figures/glass_cell_pressure.pdf",
        png=report("results/figures/glass_cell_pressure.png", caption="../report/glass_cell_pressure.rst",
                   category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_cell_pressure"),
        runtime=job_runtime("fig_glass_cell_pressure"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_cell_pressure.log",
    benchmark:
        "results/benchmarks/fig_glass_cell_pressure.tsv"
    script:
        "../scripts/plot_glass_cell_pressure.py"


rule fig_glass_separated:
    """The fully phase-separated crystal: phase densities vs overall density (Donev 2006, Fig. 13.4) and its EOS on decompression (Fig. 13.5)."""
    input:
        freezing="results/glass/freezing_summary.nc",
        decompressions=lambda w: glass_separated_files(),
    output:
        pdf="results/figures/glass_separated.pdf",
        png=report("results/figures/glass_separated.png", caption="../report/glass_separated.rst", category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_separated"),
        runtime=job_runtime("fig_glass_separated"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_separated.log",
    benchmark:
        "results/benchmarks/fig_glass_separated.tsv"
    script:
        "../scripts/plot_glass_separated.py"


rule fig_glass_relaxation:
    """Pressure relaxation of the mixture's glasses at fixed phi, per compression rate (Donev 2006, Fig. 13.7)."""
    input:
        lambda w: glass_relaxation_files(),
    output:
        pdf="results/figures/glass_relaxation.pdf",
        png=report("results/figures/glass_relaxation.png", caption="../report/glass_relaxation.rst",
                   category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_relaxation"),
        runtime=job_runtime("fig_glass_relaxation"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_relaxation.log",
    benchmark:
        "results/benchmarks/fig_glass_relaxation.tsv"
    script:
        "../scripts/plot_glass_relaxation.py"


rule fig_glass_jamming:
    """Jamming densities of the mixture vs growth rate, before and after relaxation (Donev 2006, Fig. 13.8)."""
    input:
        eos="results/glass/binary/eos_summary.nc",
        relaxed="results/glass/binary/relaxed_summary.nc",
    output:
        pdf="results/figures/glass_jamming.pdf",
        png=report("results/figures/glass_jamming.png", caption="../report/glass_jamming.rst", category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_jamming"),
        runtime=job_runtime("fig_glass_jamming"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_jamming.log",
    benchmark:
        "results/benchmarks/fig_glass_jamming.tsv"
    script:
        "../scripts/plot_glass_jamming.py"


rule fig_glass_soc:
    """EOS of the SOC solids against the slowest compression, and their phi_J before and after the cells are removed (Donev 2006, Fig. 13.9)."""
    input:
        eos="results/glass/binary/eos_summary.nc",
        soc=lambda w: glass_soc_files("ts_"),
        summary="results/glass/binary/soc_summary.nc",
    output:
        pdf="results/figures/glass_soc.pdf",
        png=report("results/figures/glass_soc.png", caption="../report/glass_soc.rst", category="5 glasses"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_glass_soc"),
        runtime=job_runtime("fig_glass_soc"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_glass_soc.log",
    benchmark:
        "results/benchmarks/fig_glass_soc.tsv"
    script:
        "../scripts/plot_glass_soc.py"
