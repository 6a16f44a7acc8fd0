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


SLP_MRJ = config.get("slp", {}).get("mrj")
if SLP_MRJ:
    for _name in SLP_MRJ["ensembles"]:
        if _name not in ENSEMBLES:
            raise ValueError(f"config: slp.mrj.ensembles names {_name!r}, which is not an ensemble")


rule slp_mrj_init:
    """Dilute RSA start (Table I: phi0 = 0.05) with the ensemble's N, d and size distribution."""
    output:
        "results/ensembles/{ensemble}/slp_init/seed{seed}.nc",
    params:
        n=lambda w: ENSEMBLES[w.ensemble]["N"],
        d=lambda w: ENSEMBLES[w.ensemble]["d"],
        phi=SLP_MRJ["init_phi"] if SLP_MRJ else None,
        distribution=lambda w: json.dumps(ENSEMBLES[w.ensemble]["distribution"]),
    log:
        "results/logs/slp_mrj_init/{ensemble}_seed{seed}.log",
    shell:
        "hardpack init --n {params.n} --d {params.d} --phi {params.phi}"
        " --distribution '{params.distribution}' --seed {wildcards.seed}"
        " --attr ensemble={wildcards.ensemble} --out {output} 2> {log}"


rule slp_mrj:
    """SLP with a deforming cell to a jammed MRJ-like packing (Table I settings from the config)."""
    input:
        "results/ensembles/{ensemble}/slp_init/seed{seed}.nc",
    output:
        packing="results/ensembles/{ensemble}/slp/seed{seed}.nc",
        history="results/ensembles/{ensemble}/slp/history_seed{seed}.nc",
    params:
        alpha=SLP_MRJ["alpha"] if SLP_MRJ else None,
        bounds=SLP_MRJ["bounds"] if SLP_MRJ else None,
    log:
        "results/logs/slp_mrj/{ensemble}_seed{seed}.log",
    shell:
        "hardpack slp --init {input} --out {output.packing} --history {output.history}"
        " --alpha {params.alpha} --strain-bound {params.bounds[strain]}"
        " --shear-bound {params.bounds[shear]} --displacement-bound {params.bounds[displacement]} 2> {log}"


rule slp_mrj_summary:
    """SLP densities of an ensemble over its seeds."""
    input:
        lambda w: expand("results/ensembles/{ensemble}/slp/seed{seed}.nc", ensemble=w.ensemble,
                         seed=ENSEMBLES[w.ensemble]["seeds"]),
    output:
        "results/ensembles/{ensemble}/slp_summary.nc",
    params:
        distribution=lambda w: json.dumps(ENSEMBLES[w.ensemble]["distribution"]),
    log:
        "results/logs/slp_mrj_summary/{ensemble}.log",
    shell:
        "hardpack combine {input} --index seed --variable n_steps --variable wall_seconds"
        " --attr ensemble={wildcards.ensemble} --attr distribution='{params.distribution}' --out {output} 2> {log}"


rule fig_slp_densest:
    """Table II: SLP densities from N = 3^d starts against the densest known packings."""
    input:
        "results/slp/densest_summary.nc",
    output:
        pdf="results/figures/slp_densest.pdf",
        png="results/figures/slp_densest.png",
    log:
        "results/logs/figures/slp_densest.log",
    script:
        "../scripts/plot_slp_densest.py"


rule fig_slp_vs_ls:
    """Table I: SLP and LS jamming densities of the same ensembles, beside the published values."""
    input:
        slp=expand("results/ensembles/{ensemble}/slp_summary.nc", ensemble=SLP_MRJ["ensembles"]) if SLP_MRJ else [],
        ls=expand("results/ensembles/{ensemble}/jammed_summary.nc", ensemble=SLP_MRJ["ensembles"]) if SLP_MRJ else [],
    output:
        pdf="results/figures/slp_vs_ls.pdf",
        png="results/figures/slp_vs_ls.png",
    log:
        "results/logs/figures/slp_vs_ls.log",
    script:
        "../scripts/plot_slp_vs_ls.py"


if SLP_DENSEST:
    FIGURES.append("results/figures/slp_densest.pdf")
    VALIDATION_INPUTS["slp_densest"] = ["results/slp/densest_summary.nc"]
if SLP_MRJ:
    FIGURES.append("results/figures/slp_vs_ls.pdf")
    VALIDATION_INPUTS["slp_mrj"] = expand("results/ensembles/{ensemble}/slp_summary.nc", ensemble=SLP_MRJ["ensembles"])
