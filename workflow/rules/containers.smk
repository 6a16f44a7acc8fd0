# Jammed spheres in spherical hard-wall containers (Donev 2006, Sec. 7.3): random starts inside the
# container, LS compression by the generic compress job (packings.smk), the radial density profile
# and core density of each packing, the Eq. 7.2 extrapolation of the average density over (N, seed),
# the window fluctuations of periodic LS packings, and the figures after Figs. 7.3, 7.5 and 7.6.


rule container_init:
    """Random sequential addition start of one container size and seed, inside a spherical container
    (or, for the system ``bulk``, in a periodic cube)."""
    output:
        "results/containers/{name}/init/seed{seed}.nc",
    params:
        n=lambda w: SYSTEMS["containers"][w.name]["N"],
        phi=lambda w: SYSTEMS["containers"][w.name]["init_phi"],
        boundary=lambda w: SYSTEMS["containers"][w.name]["boundary"],
    threads: 1
    resources:
        mem_mb=job_mem_mb("container_init"),
        runtime=job_runtime("container_init"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/container_init/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/container_init/{name}/seed{seed}.tsv"
    shell:
        "hardpack init --n {params.n} --d 3 --phi {params.phi} --boundary {params.boundary}"
        " --seed {wildcards.seed} --out {output} > {log} 2>&1"


rule container_profile:
    """phi(r) in shells of shell_width a, the average density, a/R and the core density
    (r <= R - core_margin a) of one jammed packing in a spherical container."""
    input:
        "results/containers/{name}/jammed/seed{seed}.nc",
    output:
        "results/containers/{name}/profile/seed{seed}.nc",
    params:
        shell_width=lambda w: CONTAINERS["shell_width"],
        core_margin=lambda w: CONTAINERS["core_margin"],
    threads: 1
    resources:
        mem_mb=job_mem_mb("container_profile"),
        runtime=job_runtime("container_profile"),
    group:
        "analyses"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/container_profile/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/container_profile/{name}/seed{seed}.tsv"
    script:
        "../scripts/container_profile.py"


rule container_summary:
    """The container packings over (N, seed), the Eq. 7.2 extrapolation of phi_avg to a/R -> 0
    over the sizes N >= fit_min_n with its standard error, and the density of periodic packings
    made with the same protocol (the bulk value the extrapolation estimates)."""
    input:
        profiles=container_files("profile") if CONTAINERS else [],
        bulk=container_bulk_packings() if CONTAINERS else [],
    output:
        "results/containers/profile_summary.nc",
    params:
        fit_min_n=lambda w: CONTAINERS["fit_min_n"],
    threads: 1
    resources:
        mem_mb=job_mem_mb("container_summary"),
        runtime=job_runtime("container_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/container_summary.log",
    benchmark:
        "results/benchmarks/container_summary.tsv"
    script:
        "../scripts/container_summary.py"


rule container_windows:
    """sigma_phi of random spherical windows against 2R/D in the periodic LS packings of one
    ensemble (Donev 2006, Fig. 7.3)."""
    input:
        window_packings() if CONTAINERS else [],
    output:
        "results/containers/windows_summary.nc",
    params:
        ensemble=lambda w: CONTAINERS["windows"]["ensemble"],
        seeds=lambda w: SYSTEMS["ls"][CONTAINERS["windows"]["ensemble"]]["seeds"],
        n_radii=lambda w: CONTAINERS["windows"]["n_radii"],
        min_diameter=lambda w: CONTAINERS["windows"]["min_diameter"],
        fit_min_diameter=lambda w: CONTAINERS["windows"]["fit_min_diameter"],
        n_windows=lambda w: CONTAINERS["windows"]["n_windows"],
        seed=lambda w: CONTAINERS["windows"]["seed"],
    threads: 1
    resources:
        mem_mb=job_mem_mb("container_windows"),
        runtime=job_runtime("container_windows"),
    group:
        "analyses"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/container_windows.log",
    benchmark:
        "results/benchmarks/container_windows.tsv"
    script:
        "../scripts/container_windows.py"


rule fig_container_profile:
    """phi(r) near the wall of the largest containers, with the core density 0.64 (after Donev
    2006, Fig. 7.5)."""
    input:
        lambda w: seed_files("containers", f"n{max(CONTAINERS['N'])}", "profile"),
    output:
        pdf="results/figures/container_profile.pdf",
        png=report("results/figures/container_profile.png", caption="../report/containers.rst", category="7 containers"),
    params:
        kind="profile",
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_container_profile"),
        runtime=job_runtime("fig_container_profile"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_container_profile.log",
    benchmark:
        "results/benchmarks/fig_container_profile.tsv"
    script:
        "../scripts/plot_containers.py"


rule fig_container_extrapolation:
    """phi_avg vs a/R with the linear fit and its intercept (after Donev 2006, Fig. 7.6), spheres
    and every ellipsoid shape of the config."""
    input:
        "results/containers/profile_summary.nc",
        lambda w: [f"results/ellipsoid_containers/{shape}/summary.nc"
                   for shape in (ELLIPSOID_CONTAINERS or {}).get("shapes", {})],
    output:
        pdf="results/figures/container_extrapolation.pdf",
        png=report("results/figures/container_extrapolation.png", caption="../report/containers.rst", category="7 containers"),
    params:
        kind="extrapolation",
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_container_extrapolation"),
        runtime=job_runtime("fig_container_extrapolation"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_container_extrapolation.log",
    benchmark:
        "results/benchmarks/fig_container_extrapolation.tsv"
    script:
        "../scripts/plot_containers.py"


rule fig_container_windows:
    """sigma_phi vs 2R/D, log-log, with the 0.1 (2R/D)^-2 line (after Donev 2006, Fig. 7.3)."""
    input:
        "results/containers/windows_summary.nc",
    output:
        pdf="results/figures/container_windows.pdf",
        png=report("results/figures/container_windows.png", caption="../report/containers.rst", category="7 containers"),
    params:
        kind="windows",
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_container_windows"),
        runtime=job_runtime("fig_container_windows"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_container_windows.log",
    benchmark:
        "results/benchmarks/fig_container_windows.tsv"
    script:
        "../scripts/plot_containers.py"


# Ellipsoids in spherical containers (Donev 2006, Sec. 7.3.2.1 and Fig. 7.6), one ensemble per shape
# (M&M spheroids, ollipsoids): a dilute random start inside the container, LS compression by the
# generic compress job, the radial density profile and core density of each packing (exact
# ellipsoid-ball intersection volumes), the Eq. 7.2 extrapolation of the average density
# over (N, seed), and the profiles of the largest containers after Fig. 7.5.


rule ellipsoid_container_init:
    """Dilute random start of one shape, container size and seed: bounding spheres by RSA inside
    the container, random orientations (hardpack init --semiaxes --boundary spherical_container)."""
    output:
        "results/ellipsoid_containers/{name}/init/seed{seed}.nc",
    params:
        n=lambda w: SYSTEMS["ellipsoid_containers"][w.name]["N"],
        phi=lambda w: SYSTEMS["ellipsoid_containers"][w.name]["init_phi"],
        semiaxes=lambda w: " ".join(f"{a:.17g}" for a in SYSTEMS["ellipsoid_containers"][w.name]["semiaxes"]),
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipsoid_container_init"),
        runtime=job_runtime("ellipsoid_container_init"),
    group:
        "setup"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipsoid_container_init/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/ellipsoid_container_init/{name}/seed{seed}.tsv"
    shell:
        "hardpack init --n {params.n} --d 3 --phi {params.phi} --semiaxes {params.semiaxes}"
        " --boundary spherical_container --seed {wildcards.seed} --out {output} > {log} 2>&1"


rule ellipsoid_container_profile:
    """phi(r) in shells of shell_width a (exact intersection volumes), the average density, a/R
    and the core density (r <= R - core_margin a) of one jammed ellipsoid packing in a container."""
    input:
        "results/ellipsoid_containers/{name}/jammed/seed{seed}.nc",
    output:
        "results/ellipsoid_containers/{name}/profile/seed{seed}.nc",
    params:
        shell_width=lambda w: ELLIPSOID_CONTAINERS["shell_width"],
        core_margin=lambda w: ELLIPSOID_CONTAINERS["core_margin"],
        shape_name=lambda w: SYSTEMS["ellipsoid_containers"][w.name]["attrs"]["shape_name"],
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipsoid_container_profile"),
        runtime=job_runtime("ellipsoid_container_profile"),
    group:
        "analyses"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipsoid_container_profile/{name}/seed{seed}.log",
    benchmark:
        "results/benchmarks/ellipsoid_container_profile/{name}/seed{seed}.tsv"
    script:
        "../scripts/container_profile.py"


rule ellipsoid_container_summary:
    """The container packings of one shape over (N, seed), their core densities, and the Eq. 7.2
    extrapolation of their average density to a/R -> 0 over the sizes N >= fit_min_n."""
    input:
        packings=lambda w: ellipsoid_container_files(w.shape, "jammed"),
        profiles=lambda w: ellipsoid_container_files(w.shape, "profile"),
    output:
        "results/ellipsoid_containers/{shape}/summary.nc",
    params:
        fit_min_n=lambda w: ELLIPSOID_CONTAINERS["fit_min_n"],
        shape_name=lambda w: w.shape,
    wildcard_constraints:
        shape="[a-z][a-z0-9]*",
    threads: 1
    resources:
        mem_mb=job_mem_mb("ellipsoid_container_summary"),
        runtime=job_runtime("ellipsoid_container_summary"),
    group:
        "summaries"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/ellipsoid_container_summary/{shape}.log",
    benchmark:
        "results/benchmarks/ellipsoid_container_summary/{shape}.tsv"
    script:
        "../scripts/ellipsoid_container_summary.py"


rule fig_ellipsoid_container_profile:
    """phi(r) near the wall of the largest containers of every ellipsoid shape, with each packing's
    core density and core average and Donev's bulk density of the shape (after Donev 2006,
    Fig. 7.5 and Sec. 7.3.2.1)."""
    input:
        lambda w: [path for shape in ELLIPSOID_CONTAINERS["shapes"]
                   for path in seed_files("ellipsoid_containers", f"{shape}_n{max(ELLIPSOID_CONTAINERS['N'])}",
                                          "profile")],
    output:
        pdf="results/figures/ellipsoid_container_profile.pdf",
        png=report("results/figures/ellipsoid_container_profile.png", caption="../report/containers.rst",
                   category="7 containers"),
    params:
        kind="ellipsoid_profile",
    threads: 1
    resources:
        mem_mb=job_mem_mb("fig_ellipsoid_container_profile"),
        runtime=job_runtime("fig_ellipsoid_container_profile"),
    group:
        "figures"
    conda:
        "../envs/hardpack.yaml"
    log:
        "results/logs/fig_ellipsoid_container_profile.log",
    benchmark:
        "results/benchmarks/fig_ellipsoid_container_profile.tsv"
    script:
        "../scripts/plot_containers.py"
