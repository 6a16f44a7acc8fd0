# Study 1 (SLP generator, Torquato & Jiao 2010): densest packings from N = 3^d random starts (Table II).

SLP_DENSEST = config.get("slp", {}).get("densest")
if SLP_DENSEST and len(SLP_DENSEST["d"]) != len(SLP_DENSEST["init_phi"]):
    raise ValueError("config: slp.densest.init_phi must have one entry per entry of slp.densest.d")


def slp_densest_init_phi(wildcards):
    return SLP_DENSEST["init_phi"][SLP_DENSEST["d"].index(int(wildcards.d))]


rule slp_densest_init:
    """RSA start of 3^d spheres for one Table II run."""
    output:
        "results/slp/densest/d{d}/init_seed{seed}.nc",
    params:
        phi=slp_densest_init_phi,
    log:
        "results/logs/slp_densest_init/d{d}_seed{seed}.log",
    shell:
        "hardpack init --n $((3**{wildcards.d})) --d {wildcards.d} --phi {params.phi}"
        " --seed {wildcards.seed} --attr d={wildcards.d} --out {output} 2> {log}"


rule slp_densest:
    """SLP with a deforming cell from one start (Table II settings from the config)."""
    input:
        "results/slp/densest/d{d}/init_seed{seed}.nc",
    output:
        packing="results/slp/densest/d{d}/seed{seed}.nc",
        history="results/slp/densest/d{d}/history_seed{seed}.nc",
    params:
        alpha=SLP_DENSEST["alpha"] if SLP_DENSEST else None,
        bounds=SLP_DENSEST["bounds"] if SLP_DENSEST else None,
    log:
        "results/logs/slp_densest/d{d}_seed{seed}.log",
    shell:
        "hardpack slp --init {input} --out {output.packing} --history {output.history}"
        " --alpha {params.alpha} --strain-bound {params.bounds[strain]}"
        " --shear-bound {params.bounds[shear]} --displacement-bound {params.bounds[displacement]}"
        " --attr d={wildcards.d} 2> {log}"


rule slp_densest_summary:
    """Table II reproduced: one Dataset over (d, seed)."""
    input:
        expand("results/slp/densest/d{d}/seed{seed}.nc", d=SLP_DENSEST["d"], seed=SLP_DENSEST["seeds"])
        if SLP_DENSEST else [],
    output:
        "results/slp/densest_summary.nc",
    log:
        "results/logs/slp_densest_summary.log",
    shell:
        "hardpack combine {input} --index d seed --variable n_steps --variable n_rejected"
        " --variable wall_seconds --variable converged --out {output} 2> {log}"
