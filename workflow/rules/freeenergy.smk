# Study 4: free energies by bounding-cell MD (Donev, Stillinger & Torquato 2007) for FCC crystals.

FREEENERGY = config.get("freeenergy")


rule fcc_lattice:
    """FCC crystal of 4 reps^3 spheres at contact: the cell centres of the BCMD runs."""
    output:
        "results/freeenergy/fcc_reps{reps}.nc",
    log:
        "results/logs/fcc_lattice/reps{reps}.log",
    shell:
        "hardpack lattice --name fcc --reps {wildcards.reps} --out {output} 2> {log}"


rule bcmd_fcc:
    """BCMD of FCC at the melting density (phi = 0.545) or in the jamming limit (delta = 1e-6)."""
    input:
        "results/freeenergy/fcc_reps{reps}.nc",
    output:
        "results/freeenergy/{state}/fcc_reps{reps}_seed{seed}.nc",
    wildcard_constraints:
        state="melting|jamming",
    params:
        size=lambda w: "--phi 0.545 --dmu-max 1 --theta 1" if w.state == "melting"
        else "--delta 1e-6 --dmu-max 1e-5 --theta 0.5",
        gamma0=FREEENERGY["gamma0"] if FREEENERGY else None,
    log:
        "results/logs/bcmd_fcc/{state}_reps{reps}_seed{seed}.log",
    shell:
        "hardpack bcmd {input} --out {output} {params.size} --gamma0 {params.gamma0}"
        " --seed {wildcards.seed} > {log} 2>&1"


rule bcmd_fcc_summary:
    """Free energies over (N, seed) for one state."""
    input:
        lambda w: expand("results/freeenergy/{state}/fcc_reps{reps}_seed{seed}.nc", state=w.state,
                         reps=FREEENERGY["fcc_reps"], seed=FREEENERGY["seeds"]),
    output:
        "results/freeenergy/{state}_summary.nc",
    log:
        "results/logs/bcmd_fcc_summary/{state}.log",
    shell:
        "hardpack combine {input} --index n_particles seed --variable delta_f --variable excess"
        " --variable f --variable n_events --attr state={wildcards.state} --out {output} 2> {log}"


rule fig_bcmd_fcc:
    """BCMD free energy of FCC at melting and in the jamming limit vs N, with the published values."""
    input:
        expand("results/freeenergy/{state}_summary.nc", state=["melting", "jamming"]),
    output:
        pdf="results/figures/bcmd_fcc.pdf",
        png="results/figures/bcmd_fcc.png",
    log:
        "results/logs/figures/bcmd_fcc.log",
    script:
        "../scripts/plot_bcmd_fcc.py"


STRUCTURE_FILES = [f"results/ensembles/{e}/structure/seed{s}.nc" for e in ENSEMBLES for s in ENSEMBLES[e]["seeds"]]


if FREEENERGY:
    FIGURES.append("results/figures/bcmd_fcc.pdf")
    VALIDATION_INPUTS["bcmd"] = expand("results/freeenergy/{state}_summary.nc", state=["melting", "jamming"])
