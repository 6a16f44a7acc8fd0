# Study 2: every generated packing gets an LP jamming verdict (Donev ch. 4): rattlers, contacts,
# forces, isostaticity; plus an ensemble summary.


def lp_mem_mb(wildcards):
    return 1000 + ENSEMBLES[wildcards.ensemble]["N"]


def lp_threads(wildcards):
    """Loading sequences run side by side (hardpack verify --workers) for large packings, whose
    strict sequences take a minute or more each (N = 1e4 in 3D: 1-1.5 min, 2-3 LPs)."""
    return 2 if ENSEMBLES[wildcards.ensemble]["N"] >= 5000 else 1


def lp_runtime(wildcards):
    """Minutes: collective + strict tests take ~10 s at N = 1000 (benchmarks/bench_jamming.py)."""
    return 10 + ENSEMBLES[wildcards.ensemble]["N"] // 200


rule verify_jamming:
    """LP jamming tests of one LS packing by sequential random loading (Donev Algorithm 14, meant for
    finite-rate LS packings: their near-contacts at gaps ~1e-6..1e-5 block the few floppy modes the
    linearised ideal test of the delta-contact network would report)."""
    input:
        "results/ensembles/{ensemble}/jammed/seed{seed}.nc",
    output:
        "results/ensembles/{ensemble}/jamming/seed{seed}.nc",
    threads: lp_threads
    resources:
        mem_mb=lp_mem_mb,
        runtime=lp_runtime,
    params:
        checkpoint=checkpoint_beside,
    log:
        "results/logs/verify_jamming/{ensemble}_seed{seed}.log",
    shell:
        "hardpack verify {input} --out {output} --seed {wildcards.seed} --method sequential"
        " --workers {threads} --checkpoint {params.checkpoint} > {log} 2>&1"


rule verify_jamming_slp:
    """LP jamming tests of one SLP packing (strict jamming expected: deforming cell). SLP stops when no LP step gains density, which can leave near contacts at gaps 1e-6..1e-4 D
    that block the floppy modes of the delta-contact network; the ideal test ignores them, so SLP
    packings are verified by sequential loading like LS packings (measured: a 6D N = 250 SLP
    packing with 18 such near contacts is 'not strict' by the ideal test, moving 1.5 D linearly,
    and strictly jammed by the sequential one)."""
    input:
        "results/ensembles/{ensemble}/slp/seed{seed}.nc",
    output:
        "results/ensembles/{ensemble}/slp_jamming/seed{seed}.nc",
    threads: 1
    resources:
        mem_mb=lp_mem_mb,
        runtime=lp_runtime,
    params:
        checkpoint=checkpoint_beside,
    log:
        "results/logs/verify_jamming_slp/{ensemble}_seed{seed}.log",
    shell:
        "hardpack verify {input} --out {output} --seed {wildcards.seed} --method sequential"
        " --checkpoint {params.checkpoint} > {log} 2>&1"


rule jamming_summary:
    """Verdicts, Z, rattler fractions and isostaticity gaps of an ensemble, indexed by seed."""
    input:
        lambda w: expand("results/ensembles/{ensemble}/{kind}/seed{seed}.nc", ensemble=w.ensemble,
                         kind=w.kind, seed=ENSEMBLES[w.ensemble]["seeds"]),
    output:
        "results/ensembles/{ensemble}/{kind}_summary.nc",
    wildcard_constraints:
        kind="jamming|slp_jamming",
    params:
        distribution=lambda w: json.dumps(ENSEMBLES[w.ensemble]["distribution"]),
        seeds=lambda w: ENSEMBLES[w.ensemble]["seeds"],
    log:
        "results/logs/jamming_summary/{ensemble}_{kind}.log",
    shell:
        "hardpack combine {input} --index seed --variable z_mean --variable rattler_fraction"
        " --variable isostaticity_gap --variable local --variable collective --variable strict"
        " --variable fallback_lp_default_tolerances --variable fallback_lp_working_set_to_highs"
        " --variable fallback_uniform_forces_lp_failed --attr ensemble={wildcards.ensemble} --attr distribution='{params.distribution}'"
        " --out {output} 2> {log}"

VALIDATION_INPUTS["jamming"] = expand("results/ensembles/{ensemble}/jamming_summary.nc", ensemble=ENSEMBLES)

MONODISPERSE = [name for name, ens in ENSEMBLES.items() if ens["distribution"]["kind"] == "monodisperse"]


rule fig_jamming_vs_d:
    """phi_J and the contact number after rattlers of the monodisperse LS ensembles vs dimension."""
    input:
        jammed=expand("results/ensembles/{ensemble}/jammed_summary.nc", ensemble=MONODISPERSE),
        verdicts=expand("results/ensembles/{ensemble}/jamming_summary.nc", ensemble=MONODISPERSE),
    output:
        pdf="results/figures/jamming_vs_d.pdf",
        png=report("results/figures/jamming_vs_d.png", caption="../report/jamming_vs_d.rst", category="2 jamming"),
    log:
        "results/logs/figures/jamming_vs_d.log",
    script:
        "../scripts/plot_jamming_vs_d.py"


if MONODISPERSE:
    FIGURES.append("results/figures/jamming_vs_d.pdf")
