# Study 4: free energies by bounding-cell MD (Donev, Stillinger & Torquato 2007): FCC crystals
# (finite-N extrapolation at melting and jamming, free energy vs density against the crystal's
# EOS integrated from the published melting value) and LS packings against their exact simplex.

import math

FREEENERGY = config.get("freeenergy")
PHI_CP = math.pi / math.sqrt(18)


def fcc_dmu_max(phi):
    """Initial cell size: the paper's 1 at melting, 10 disjoint-cell points near jamming."""
    return min(1.0, 10.0 * ((PHI_CP / float(phi)) ** (1 / 3) - 1))


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
    threads: 1
    resources:
        mem_mb=500,
        runtime=20,
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
    wildcard_constraints:
        state="melting|jamming",
    log:
        "results/logs/bcmd_fcc_summary/{state}.log",
    shell:
        "hardpack combine {input} --index n_particles seed --variable delta_f --variable excess"
        " --variable f --variable n_events --variable seconds --attr state={wildcards.state}"
        " --out {output} 2> {log}"


rule fig_bcmd_fcc:
    """BCMD free energy of FCC at melting and in the jamming limit vs N, with the published values."""
    input:
        expand("results/freeenergy/{state}_summary.nc", state=["melting", "jamming"]),
    output:
        pdf="results/figures/bcmd_fcc.pdf",
        png=report("results/figures/bcmd_fcc.png", caption="../report/bcmd_fcc.rst", category="4 free energies"),
    log:
        "results/logs/figures/bcmd_fcc.log",
    script:
        "../scripts/plot_bcmd_fcc.py"


rule bcmd_fcc_density:
    """BCMD of FCC at one density, from dmu_max (fcc_dmu_max) to the disjoint-cell point."""
    input:
        "results/freeenergy/fcc_reps{reps}.nc",
    output:
        "results/freeenergy/density/fcc_reps{reps}_phi{phi}_seed{seed}.nc",
    params:
        dmu_max=lambda w: fcc_dmu_max(w.phi),
        gamma0=FREEENERGY["gamma0"] if FREEENERGY else None,
    threads: 1
    resources:
        mem_mb=500,
        runtime=20,
    log:
        "results/logs/bcmd_fcc_density/reps{reps}_phi{phi}_seed{seed}.log",
    shell:
        "hardpack bcmd {input} --out {output} --phi {wildcards.phi} --dmu-max {params.dmu_max}"
        " --theta 1 --gamma0 {params.gamma0} --seed {wildcards.seed} > {log} 2>&1"


rule fcc_eos:
    """Equation of state Z(phi) of the FCC crystal (plain MD, no cells) at one density."""
    input:
        "results/freeenergy/fcc_reps{reps}.nc",
    output:
        "results/freeenergy/eos/fcc_reps{reps}_phi{phi}.nc",
    params:
        collisions=FREEENERGY["density"]["eos_collisions"] if FREEENERGY else None,
    threads: 1
    resources:
        mem_mb=500,
        runtime=20,
    log:
        "results/logs/fcc_eos/reps{reps}_phi{phi}.log",
    shell:
        "hardpack eos --init {input} --phi {wildcards.phi} --seed 1"
        " --collisions {params.collisions} --out {output} 2> {log}"


def density_files(kind):
    dens = FREEENERGY["density"]
    if kind == "bcmd":
        return expand("results/freeenergy/density/fcc_reps{reps}_phi{phi}_seed{seed}.nc",
                      reps=dens["reps"], phi=dens["phi"], seed=dens["seeds"])
    return expand("results/freeenergy/eos/fcc_reps{reps}_phi{phi}.nc", reps=dens["reps"],
                  phi=dens["phi"])


rule bcmd_density_summary:
    """BCMD free energies and the MD equation of state of FCC over the densities."""
    input:
        bcmd=density_files("bcmd") if FREEENERGY else [],
        eos=density_files("eos") if FREEENERGY else [],
    output:
        bcmd="results/freeenergy/density_bcmd_summary.nc",
        eos="results/freeenergy/density_eos_summary.nc",
    log:
        "results/logs/bcmd_density_summary.log",
    shell:
        "hardpack combine {input.bcmd} --index phi seed --variable delta_f --variable excess"
        " --variable n_particles --variable n_events --variable seconds --attr state=density"
        " --out {output.bcmd} 2> {log} && hardpack combine {input.eos} --index phi --variable Z"
        " --variable Z_err --variable N --variable wall_time --attr state=eos --out {output.eos} 2>> {log}"


rule fig_bcmd_density:
    """FCC free energy vs density: BCMD, EOS integration from the published melting value, cell limit."""
    input:
        bcmd="results/freeenergy/density_bcmd_summary.nc",
        eos="results/freeenergy/density_eos_summary.nc",
    output:
        pdf="results/figures/bcmd_fcc_density.pdf",
        png=report("results/figures/bcmd_fcc_density.png", caption="../report/bcmd_fcc_density.rst", category="4 free energies"),
    log:
        "results/logs/figures/bcmd_fcc_density.log",
    script:
        "../scripts/plot_bcmd_density.py"


rule bcmd_simplex:
    """BCMD of an LS packing's rattler-free backbone vs its exact jamming simplex (Table 6.1)."""
    input:
        packing="results/ensembles/{ensemble}/jammed/seed{seed}.nc",
        verdict="results/ensembles/{ensemble}/jamming/seed{seed}.nc",
    output:
        "results/freeenergy/simplex/{ensemble}_seed{seed}_{frozen}.nc",
    wildcard_constraints:
        frozen="particle|cm",
    params:
        s=FREEENERGY["simplex"] if FREEENERGY else None,
    threads: 1
    resources:
        mem_mb=1000,
        runtime=30,
    log:
        "results/logs/bcmd_simplex/{ensemble}_seed{seed}_{frozen}.log",
    shell:
        "hardpack bcmd-simplex {input.packing} --jamming {input.verdict} --out {output}"
        " --delta {params.s[delta]} --dmu-max-ratio {params.s[dmu_max_ratio]}"
        " --gamma0 {params.s[gamma0]} --theta {params.s[theta]} --frozen {wildcards.frozen}"
        " --seed {wildcards.seed} > {log} 2>&1"


rule bcmd_simplex_summary:
    """BCMD vs exact simplex over packings and translation modes."""
    input:
        lambda w: expand("results/freeenergy/simplex/{ensemble}_seed{seed}_{frozen}.nc",
                         ensemble=FREEENERGY["simplex"]["ensemble"],
                         seed=FREEENERGY["simplex"]["seeds"], frozen=["particle", "cm"]),
    output:
        "results/freeenergy/simplex_summary.nc",
    log:
        "results/logs/bcmd_simplex_summary.log",
    shell:
        "hardpack combine {input} --index seed frozen --variable exact --variable bcmd"
        " --variable rel_diff --variable isostatic --variable isostaticity_gap"
        " --variable n_backbone --variable dim --variable n_events --variable seconds_bcmd"
        " --variable next_gap"
        " --out {output} 2> {log}"


rule bcmd_ladder:
    """The cheap BCMD checks against exact values (disjoint cells, billiard, simplex formula)."""
    output:
        "results/freeenergy/ladder.nc",
    threads: 1
    resources:
        mem_mb=500,
        runtime=10,
    log:
        "results/logs/bcmd_ladder.log",
    shell:
        "hardpack bcmd-ladder --out {output} > {log} 2>&1"


if FREEENERGY:
    FIGURES.append("results/figures/bcmd_fcc.pdf")
    FIGURES.append("results/figures/bcmd_fcc_density.pdf")
    VALIDATION_INPUTS["bcmd"] = expand("results/freeenergy/{state}_summary.nc", state=["melting", "jamming"])
    VALIDATION_INPUTS["bcmd_density"] = ["results/freeenergy/density_bcmd_summary.nc",
                                         "results/freeenergy/density_eos_summary.nc"]
    VALIDATION_INPUTS["bcmd_simplex"] = ["results/freeenergy/simplex_summary.nc"]
    VALIDATION_INPUTS["bcmd_ladder"] = ["results/freeenergy/ladder.nc"]
