# Study 1 (LS generator): event-driven MD with Lubachevsky-Stillinger growth, one jammed packing
# per (ensemble, seed), and the ensemble summary of jamming densities.


rule compress:
    """LS compression of one start configuration to the configured reduced pressure.

    The checkpoint lets a killed job resume where it stopped (it is removed on success).
    """
    input:
        "results/ensembles/{ensemble}/init/seed{seed}.nc",
    output:
        packing="results/ensembles/{ensemble}/jammed/seed{seed}.nc",
        timeseries="results/ensembles/{ensemble}/timeseries/seed{seed}.nc",
    params:
        growth_rate=lambda w: ENSEMBLES[w.ensemble]["growth_rate"],
        max_pressure=lambda w: ENSEMBLES[w.ensemble]["max_pressure"],
        checkpoint="results/ensembles/{ensemble}/checkpoints/seed{seed}.ckpt",
    log:
        "results/logs/compress/{ensemble}_seed{seed}.log",
    shell:
        "hardpack compress --init {input} --out {output.packing} --timeseries {output.timeseries}"
        " --growth-rate {params.growth_rate} --seed {wildcards.seed} --max-pressure {params.max_pressure}"
        " --checkpoint {params.checkpoint} 2> {log} && rm -f {params.checkpoint}"


def jammed_files(wildcards):
    seeds = ENSEMBLES[wildcards.ensemble]["seeds"]
    return expand("results/ensembles/{ensemble}/jammed/seed{seed}.nc", ensemble=wildcards.ensemble, seed=seeds)


rule jammed_summary:
    """phi_J, final Z and collision counts of an ensemble, indexed by seed."""
    input:
        jammed_files,
    output:
        "results/ensembles/{ensemble}/jammed_summary.nc",
    params:
        distribution=lambda w: json.dumps(ENSEMBLES[w.ensemble]["distribution"]),
    log:
        "results/logs/jammed_summary/{ensemble}.log",
    shell:
        "hardpack combine {input} --index seed --variable Z --variable phi_J_est --variable collisions"
        " --variable wall_time --variable growth_rate --attr ensemble={wildcards.ensemble}"
        " --attr distribution='{params.distribution}' --out {output} 2> {log}"

VALIDATION_INPUTS["ls"] = expand("results/ensembles/{ensemble}/jammed_summary.nc", ensemble=ENSEMBLES)
