# Study 1 (LS generator): event-driven MD with Lubachevsky-Stillinger growth, one jammed packing
# per (ensemble, seed), and the ensemble summary of jamming densities.


def ls_mem_mb(wildcards):
    return 500 + ENSEMBLES[wildcards.ensemble]["N"] // 5


def ls_runtime(wildcards):
    """Minutes: the slow final stage costs ~N / 20 minutes on one core (3D, Gamma_f = 1e-4)."""
    return 30 + ENSEMBLES[wildcards.ensemble]["N"] // 10


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
        final=lambda w: "--final-growth-rate {final_growth_rate} --switch-pressure {switch_pressure}".format(
            **ENSEMBLES[w.ensemble]) if "final_growth_rate" in ENSEMBLES[w.ensemble] else "",
        checkpoint="results/ensembles/{ensemble}/checkpoints/seed{seed}.ckpt",
    threads: 1
    resources:
        mem_mb=ls_mem_mb,
        runtime=ls_runtime,
    log:
        "results/logs/compress/{ensemble}_seed{seed}.log",
    shell:
        "hardpack compress --init {input} --out {output.packing} --timeseries {output.timeseries}"
        " --growth-rate {params.growth_rate} {params.final} --seed {wildcards.seed}"
        " --max-pressure {params.max_pressure} --contact-forces --checkpoint {params.checkpoint} 2> {log} && rm -f {params.checkpoint}"


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


# Growth-rate scan (Donev Fig. 1.3): single-stage LS compressions of one ensemble's starts at
# several Gamma; their time series give phi_J estimate vs phi and Z vs phi against theory.
RATES = config.get("rates")
if RATES and RATES["ensemble"] not in ENSEMBLES:
    raise ValueError(f"config: rates.ensemble {RATES['ensemble']!r} is not one of the ensembles {sorted(ENSEMBLES)}")


def rate_timeseries(wildcards=None):
    return expand("results/rates/{ensemble}/gamma{gamma}/timeseries_seed{seed}.nc", ensemble=RATES["ensemble"],
                  gamma=RATES["growth_rates"], seed=RATES["seeds"])


rule compress_rate:
    """Single-stage LS compression of an ensemble's start at one growth rate of the scan."""
    input:
        "results/ensembles/{ensemble}/init/seed{seed}.nc",
    output:
        packing="results/rates/{ensemble}/gamma{gamma}/seed{seed}.nc",
        timeseries="results/rates/{ensemble}/gamma{gamma}/timeseries_seed{seed}.nc",
    params:
        max_pressure=lambda w: ENSEMBLES[w.ensemble]["max_pressure"],
        checkpoint="results/rates/{ensemble}/gamma{gamma}/seed{seed}.ckpt",
    threads: 1
    resources:
        mem_mb=ls_mem_mb,
        runtime=ls_runtime,
    log:
        "results/logs/compress_rate/{ensemble}_gamma{gamma}_seed{seed}.log",
    shell:
        "hardpack compress --init {input} --out {output.packing} --timeseries {output.timeseries}"
        " --growth-rate {wildcards.gamma} --seed {wildcards.seed} --max-pressure {params.max_pressure}"
        " --checkpoint {params.checkpoint} 2> {log} && rm -f {params.checkpoint}"


rule fig_rates:
    """Fig. 1.3 of Donev: phi_J estimate phi / (1 - d/Z) vs phi for each Gamma (kind=phij), or the
    reduced pressure Z vs phi against Carnahan-Starling and the free-volume law (kind=eos)."""
    input:
        rate_timeseries,
    output:
        pdf="results/figures/ls_rates_{kind}.pdf",
        png=report("results/figures/ls_rates_{kind}.png", caption="../report/ls_rates.rst", category="1 generation"),
    wildcard_constraints:
        kind="phij|eos",
    log:
        "results/logs/figures/ls_rates_{kind}.log",
    script:
        "../scripts/plot_rates.py"


if RATES:
    FIGURES += expand("results/figures/ls_rates_{kind}.pdf", kind=["phij", "eos"])
