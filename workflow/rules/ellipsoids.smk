# Hard ellipsoids and ellipses (Donev 2006, Sec. 5.2): the contacts and jamming verdicts of the LS
# packings (the init and compress jobs are the generic ones of packings.smk) and the figures after
# Figs. 5.1-5.3.


rule ellipsoid_contacts:
    """Contacts within contact_tol of touching, rattlers removed iteratively, mean contact number
    and nematic order of one jammed ellipsoid or ellipse packing."""
    input:
        "results/ellipsoids/{name}/jammed/seed{seed}.nc",
    output:
        "results/ellipsoids/{name}/contacts/seed{seed}.nc",
    params:
        tol=lambda w: ELLIPSOIDS["contact_tol"],
        attrs=lambda w: SYSTEMS["ellipsoids"][w.name]["attrs"],
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipsoid_contacts"),
        runtime=job_runtime("ellipsoid_contacts"),
    group:
        "analyses"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipsoid_contacts/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/ellipsoid_contacts/{name}/seed{seed}.tsv"
    script:
        "../scripts/ellipsoid_contacts.py"


rule ellipsoid_verify:
    """First- and second-order jamming tests of one jammed ellipsoid or ellipse packing (Donev 2006,
    Secs. 5.5.3 and 5.6), contacts from the gap distribution, at the jamming point of the contacts
    when Newton's method reaches it without overlaps (hardpack.jamming.refine); the verdict states
    the order that decided it."""
    input:
        "results/ellipsoids/{name}/jammed/seed{seed}.nc",
    output:
        "results/ellipsoids/{name}/verdict/seed{seed}.nc",
    params:
        attrs=lambda w: attr_options(SYSTEMS["ellipsoids"][w.name]["attrs"]),
        ascent=lambda w: (f"--ascent-max-particles {int(ELLIPSOIDS['ascent_max_particles'])}"
                          if "ascent_max_particles" in ELLIPSOIDS else ""),
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipsoid_verify"),
        runtime=job_runtime("ellipsoid_verify"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipsoid_verify/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/ellipsoid_verify/{name}/seed{seed}.tsv"
    shell:
        "hardpack verify {input} --out {output} --delta gaps --refine {params.ascent} --seed {wildcards.seed} "
        "{params.attrs} > {log} 2>&1"


rule ellipsoid_verdict_fractions:
    """Per shape: the fractions of packings jammed and decided at first or second order, backbone
    Z and rattler fraction (hardpack.jamming.ellipsoid_verdicts)."""
    input:
        summary("ellipsoids/verdicts{part}"),
    output:
        "results/ellipsoids/verdict_fractions{part}.nc",
    wildcard_constraints:
        part="2d|3d|_near_sphere",
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipsoid_verdict_fractions"),
        runtime=job_runtime("ellipsoid_verdict_fractions"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipsoid_verdict_fractions/{part}.log",
    benchmark:
        "results/benchmarks/ellipsoid_verdict_fractions/{part}.tsv"
    script:
        "../scripts/ellipsoid_verdict_fractions.py"


rule fig_ellipsoid_jamming:
    """phi_J and Z vs aspect ratio of every ellipsoid family (after Donev 2006, Fig. 5.2)."""
    input:
        summary("ellipsoids/contacts3d"),
    output:
        pdf="results/figures/ellipsoid_jamming.pdf",
        png=report("results/figures/ellipsoid_jamming.png", caption="../report/ellipsoid_jamming.rst", category="6 ellipsoids"),
    params:
        dim=3,
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_ellipsoid_jamming"),
        runtime=job_runtime("fig_ellipsoid_jamming"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_ellipsoid_jamming.log",
    benchmark:
        "results/benchmarks/fig_ellipsoid_jamming.tsv"
    script:
        "../scripts/plot_ellipsoid_jamming.py"


rule fig_ellipse_jamming:
    """phi_J and Z vs aspect ratio of the binary ellipses (after Donev 2006, Fig. 5.3)."""
    input:
        summary("ellipsoids/contacts2d"),
    output:
        pdf="results/figures/ellipse_jamming.pdf",
        png=report("results/figures/ellipse_jamming.png", caption="../report/ellipsoid_jamming.rst", category="6 ellipsoids"),
    params:
        dim=2,
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_ellipse_jamming"),
        runtime=job_runtime("fig_ellipse_jamming"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_ellipse_jamming.log",
    benchmark:
        "results/benchmarks/fig_ellipse_jamming.tsv"
    script:
        "../scripts/plot_ellipsoid_jamming.py"


rule fig_ellipsoid_snapshot:
    """A jammed packing of M&M-shaped oblate spheroids (after Donev 2006, Fig. 5.1)."""
    input:
        lambda w: seed_files("ellipsoids", mm_system(), "jammed")[0],
    output:
        pdf="results/figures/ellipsoid_snapshot.pdf",
        png=report("results/figures/ellipsoid_snapshot.png", caption="../report/ellipsoid_snapshot.rst", category="6 ellipsoids"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_ellipsoid_snapshot"),
        runtime=job_runtime("fig_ellipsoid_snapshot"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_ellipsoid_snapshot.log",
    benchmark:
        "results/benchmarks/fig_ellipsoid_snapshot.tsv"
    script:
        "../scripts/plot_ellipsoid_snapshot.py"


rule laminate_family:
    """The laminate crystals of spheroids vs aspect ratio, with sqrt(3) and the stretched densest
    laminate beyond it (Donev 2006, Sec. 8.2, Eqs. 8.1-8.3)."""
    output:
        "results/ellipsoid_crystals/laminate_family.nc",
    params:
        alpha_max=lambda w: ELLIPSOID_CRYSTALS["alpha_max"],
        alpha_step=lambda w: ELLIPSOID_CRYSTALS["alpha_step"],
    threads: 1
    resources:
        mem_mb=job_mem_mb("laminate_family"),
        runtime=job_runtime("laminate_family"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/laminate_family.log",
    benchmark:
        "results/benchmarks/laminate_family.tsv"
    shell:
        "hardpack laminate --alpha-max {params.alpha_max} --alpha-step {params.alpha_step}"
        " --out {output} > {log} 2>&1"


rule crystal_search:
    """Dense spheroid crystals from random starts in small deforming cells, every n per cell and
    seed of one aspect ratio (Donev 2006, Sec. 8.2.1)."""
    output:
        "results/ellipsoid_crystals/search/alpha{alpha}.nc",
    wildcard_constraints:
        alpha=r"[0-9.]+",
    params:
        n=lambda w: " ".join(str(n) for n in CRYSTAL_SEARCH["n"]),
        seeds=lambda w: " ".join(str(s) for s in CRYSTAL_SEARCH["seeds"]),
    threads: 1
    resources:
        mem_mb=job_mem_mb("crystal_search"),
        runtime=job_runtime("crystal_search"),
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/crystal_search/alpha{alpha}.log",
    benchmark:
        "results/benchmarks/crystal_search/alpha{alpha}.tsv"
    shell:
        "hardpack crystal-search --alpha {wildcards.alpha} --n {params.n} --seeds {params.seeds}"
        " --out {output} > {log} 2>&1"


rule fig_laminate_crystals:
    """Density of the laminate crystals vs aspect ratio (after Donev 2006, Fig. 8.2)."""
    input:
        family="results/ellipsoid_crystals/laminate_family.nc",
        searches=crystal_search_outputs(),
    output:
        pdf="results/figures/laminate_crystals.pdf",
        png=report("results/figures/laminate_crystals.png", caption="../report/laminate_crystals.rst", category="6 ellipsoids"),
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_laminate_crystals"),
        runtime=job_runtime("fig_laminate_crystals"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_laminate_crystals.log",
    benchmark:
        "results/benchmarks/fig_laminate_crystals.tsv"
    script:
        "../scripts/plot_laminate_crystals.py"
