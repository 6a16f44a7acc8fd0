# Free energies by bounding-cell MD (Donev, Stillinger & Torquato 2007): FCC crystals (finite-N
# extrapolation at melting and jamming, free energy vs density against the crystal's EOS
# integrated from the published melting value) and LS packings against their exact simplex.


rule lattice:
    """FCC crystal of 4 reps^3 spheres at contact: the cell centres of the BCMD runs."""
    output:
        "results/bcmd_fcc/reps{reps}/lattice.nc",
    threads: 1
    resources:
        mem_mb=job_mem_mb("lattice"),
        runtime=job_runtime("lattice"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/lattice/reps{reps}.log",
    benchmark:
        "results/benchmarks/lattice/reps{reps}.tsv"
    shell:
        "hardpack lattice --name fcc --reps {wildcards.reps} --out {output} > {log} 2>&1"


rule bcmd_fcc:
    """BCMD of FCC at the melting density (phi = 0.545), in the jamming limit (delta = 1e-6), or at
    one density phi{phi} from dmu_max (fcc_dmu_max) to the disjoint-cell point."""
    input:
        "results/bcmd_fcc/reps{reps}/lattice.nc",
    output:
        "results/bcmd_fcc/reps{reps}/{condition}/seed{seed}.nc",
    wildcard_constraints:
        condition=r"melting|jamming|phi[0-9.]+",
    params:
        size=bcmd_options,
        gamma0=FREEENERGY["gamma0"] if FREEENERGY else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("bcmd_fcc"),
        runtime=job_runtime("bcmd_fcc"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/bcmd_fcc/reps{reps}/{condition}/seed{seed}.log",
    benchmark:
        "results/benchmarks/bcmd_fcc/reps{reps}/{condition}/seed{seed}.tsv"
    shell:
        "hardpack bcmd {input} --out {output} {params.size} --gamma0 {params.gamma0}"
        " --seed {wildcards.seed} > {log} 2>&1"


rule fcc_eos:
    """Equation of state Z(phi) of the FCC crystal (plain MD, no cells) at one density."""
    input:
        "results/bcmd_fcc/reps{reps}/lattice.nc",
    output:
        "results/bcmd_fcc/reps{reps}/eos/phi{phi}.nc",
    params:
        collisions=FREEENERGY["density"]["eos_collisions"] if FREEENERGY else None,
        checkpoint=checkpoint_beside,
    threads: 1
    resources:
        mem_mb=job_mem_mb("fcc_eos"),
        runtime=job_runtime("fcc_eos"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fcc_eos/reps{reps}/phi{phi}.log",
    benchmark:
        "results/benchmarks/fcc_eos/reps{reps}/phi{phi}.tsv"
    shell:
        "hardpack eos --init {input} --phi {wildcards.phi} --seed 1"
        " --collisions {params.collisions} --out {output} --checkpoint {params.checkpoint} > {log} 2>&1"


rule bcmd_simplex:
    """BCMD of an LS packing's rattler-free backbone vs its exact jamming simplex (Table 6.1)."""
    input:
        packing="results/ls/{ensemble}/jammed/seed{seed}.nc",
        verdict="results/ls/{ensemble}/verdict/seed{seed}.nc",
    output:
        "results/bcmd_simplex/{ensemble}/{frozen}/seed{seed}.nc",
    wildcard_constraints:
        frozen="particle|cm",
    params:
        s=FREEENERGY["simplex"] if FREEENERGY else None,
    threads: 1
    resources:
        mem_mb=job_mem_mb("bcmd_simplex"),
        runtime=job_runtime("bcmd_simplex"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/bcmd_simplex/{ensemble}/{frozen}/seed{seed}.log",
    benchmark:
        "results/benchmarks/bcmd_simplex/{ensemble}/{frozen}/seed{seed}.tsv"
    shell:
        "hardpack bcmd-simplex {input.packing} --jamming {input.verdict} --out {output}"
        " --delta {params.s[delta]} --dmu-max-ratio {params.s[dmu_max_ratio]}"
        " --gamma0 {params.s[gamma0]} --theta {params.s[theta]} --frozen {wildcards.frozen}"
        " --seed {wildcards.seed} > {log} 2>&1"


rule bcmd_ladder:
    """The cheap BCMD checks against exact values (disjoint cells, billiard, simplex formula)."""
    output:
        "results/bcmd_ladder/ladder.nc",
    threads: 1
    resources:
        mem_mb=job_mem_mb("bcmd_ladder"),
        runtime=job_runtime("bcmd_ladder"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/bcmd_ladder.log",
    benchmark:
        "results/benchmarks/bcmd_ladder.tsv"
    shell:
        "hardpack bcmd-ladder --out {output} > {log} 2>&1"


rule fig_bcmd_fcc:
    """BCMD free energy of FCC at melting and in the jamming limit vs N, with the published values."""
    input:
        summary("bcmd_fcc/melting"),
        summary("bcmd_fcc/jamming"),
    output:
        pdf="results/figures/bcmd_fcc.pdf",
        png=report("results/figures/bcmd_fcc.png", caption="../report/bcmd_fcc.rst", category="4 free energies"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_bcmd_fcc"),
        runtime=job_runtime("fig_bcmd_fcc"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_bcmd_fcc.log",
    benchmark:
        "results/benchmarks/fig_bcmd_fcc.tsv"
    script:
        "../scripts/plot_bcmd_fcc.py"


rule fig_bcmd_density:
    """FCC free energy vs density: BCMD, EOS integration from the published melting value, cell limit."""
    input:
        bcmd=summary("bcmd_fcc/density"),
        eos=summary("bcmd_fcc/eos"),
    output:
        pdf="results/figures/bcmd_fcc_density.pdf",
        png=report("results/figures/bcmd_fcc_density.png", caption="../report/bcmd_fcc_density.rst", category="4 free energies"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_bcmd_density"),
        runtime=job_runtime("fig_bcmd_density"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_bcmd_density.log",
    benchmark:
        "results/benchmarks/fig_bcmd_density.tsv"
    script:
        "../scripts/plot_bcmd_density.py"


rule ellipse_lattice:
    """Start of the isostatic ellipse packing (Donev 2006, sec. 6.4.3): a triangular lattice of 100
    disks turned into alpha = 2 ellipses, orientations uniform in +-0.3 rad."""
    output:
        "results/bcmd_ellipse/seed{seed}/start.nc",
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipse_lattice"),
        runtime=job_runtime("ellipse_lattice"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipse_lattice/seed{seed}.log",
    benchmark:
        "results/benchmarks/ellipse_lattice/seed{seed}.tsv"
    shell:
        "hardpack ellipse-lattice --seed {wildcards.seed} --out {output} > {log} 2>&1"


rule ellipse_lattice_jam:
    """The lattice ellipses compressed to jamming by ellipse LS MD (two-stage protocol)."""
    input:
        "results/bcmd_ellipse/seed{seed}/start.nc",
    output:
        "results/bcmd_ellipse/seed{seed}/jammed.nc",
    params:
        e=FREEENERGY.get("ellipse") if FREEENERGY else None,
        checkpoint=checkpoint_beside,
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipse_lattice_jam"),
        runtime=job_runtime("ellipse_lattice_jam"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipse_lattice_jam/seed{seed}.log",
    benchmark:
        "results/benchmarks/ellipse_lattice_jam/seed{seed}.tsv"
    shell:
        "hardpack compress --init {input} --out {output} --growth-rate 1e-2 --final-growth-rate 1e-3"
        " --switch-pressure 1e3 --max-pressure {params.e[max_pressure]} --seed {wildcards.seed}"
        " --checkpoint {params.checkpoint} > {log} 2>&1"


rule bcmd_ellipse:
    """The jammed lattice ellipses made isostatic by frozen particles: exact simplex and linearised
    BCMD at the published parameters (Donev 2006, sec. 6.4.3)."""
    input:
        "results/bcmd_ellipse/seed{seed}/jammed.nc",
    output:
        "results/bcmd_ellipse/seed{seed}/bcmd.nc",
    params:
        e=FREEENERGY.get("ellipse") if FREEENERGY else None,
        exact_only=lambda w: "--exact-only" if FREEENERGY["ellipse"].get("exact_only") else "",
    threads: 1
    resources:
        mem_mb=job_mem_mb("bcmd_ellipse"),
        runtime=job_runtime("bcmd_ellipse"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/bcmd_ellipse/seed{seed}.log",
    benchmark:
        "results/benchmarks/bcmd_ellipse/seed{seed}.tsv"
    shell:
        "hardpack bcmd-ellipse {input} --out {output} --delta {params.e[delta]}"
        " --dmu-max {params.e[dmu_max]} --gamma0 {params.e[gamma0]} --theta {params.e[theta]}"
        " --freeze-seed {wildcards.seed} --seed {wildcards.seed} {params.exact_only} > {log} 2>&1"


rule bcmd_ellipse_ladder:
    """Independent ellipses in shrinking cells of their own shape (the disjoint-cell rung)."""
    output:
        "results/bcmd_ellipse/ladder.nc",
    threads: 1
    resources:
        mem_mb=job_mem_mb("bcmd_ellipse_ladder"),
        runtime=job_runtime("bcmd_ellipse_ladder"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/bcmd_ellipse_ladder.log",
    benchmark:
        "results/benchmarks/bcmd_ellipse_ladder.tsv"
    shell:
        "hardpack bcmd-ellipse-ladder --out {output} > {log} 2>&1"
