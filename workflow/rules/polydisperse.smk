# Study 3 (issue 6): EOS and jamming density of polydisperse spheres vs their moment-matched bi- and
# tridisperse equivalents (Ogarko ch. 3). One job per (family, width, seed, system) jams the
# polydisperse system or one of its equivalents, all with the same protocol and N (a checkpoint lets a
# killed job resume: the slow runs take up to ~20 CPU min each); one job per (family, width) measures the
# fluid Z(phi) of the three against BMCSL. The same jobs with a slow final stage ("crystallisation")
# look for the large-species crystallisation of the bidisperse equivalents (Ogarko L4851-4865).
# Summaries, figures and validation rows follow.

POLY = config.get("polydisperse", {})
POLY_JAM = POLY.get("jam", {})
#: jam protocols by output folder: the equivalence runs and the slow crystallisation runs
POLY_PROTOCOLS = {"jammed": POLY_JAM, "crystallisation": POLY.get("crystallisation", {})}
POLY_FLUID = POLY.get("fluid", {})
POLY_SYSTEMS = ["poly", "bi", "tri"]
POLY_WIDTH_NAME = {"uniform_size": "omega", "uniform_volume": "omega", "lognormal": "sigma"}


def _poly_width(value):
    return f"{float(value):g}"


def _poly_spec(family, width):
    return json.dumps({"kind": family, POLY_WIDTH_NAME[family]: float(width)})


def _poly_jam_files(protocol, family):
    runs = POLY_PROTOCOLS[protocol]
    return expand("results/polydisperse/{protocol}/{family}/w{width}/seed{seed}_{system}.nc", protocol=protocol,
                  family=family, width=[_poly_width(w) for w in runs["widths"][family]], seed=runs["seeds"],
                  system=POLY_SYSTEMS)


POLY_FAMILY = "uniform_size|uniform_volume|lognormal"
POLY_WIDTH = r"[0-9]+(\.[0-9]+)?"


def poly_jam_mem_mb(wildcards):
    return 500 + POLY_PROTOCOLS[wildcards.protocol]["N"] // 5


def poly_jam_runtime(wildcards):
    """Minutes for one system. Measured: 3-11 CPU s at N = 500 (US omega = 2 and 10, final Gamma =
    0.002), 6-7 CPU min at final Gamma = 2e-5 and 13-18 at 1e-5; the collisions grow as N / Gamma, and
    the budget is ~20x the measured time at Gamma = 0.002, for loaded machines and wide UV
    distributions."""
    runs = POLY_PROTOCOLS[wildcards.protocol]
    return 10 + int(runs["N"] // 100 * max(1.0, 0.002 / runs["final_growth_rate"]))


def poly_fluid_runtime(wildcards):
    """Minutes: 3 systems x len(phi) runs of `collisions` collisions at ~1e6 collisions per CPU second."""
    runs = 3 * len(POLY_FLUID["phi"])
    return 10 + runs * (POLY_FLUID["collisions"] + 50 * POLY_FLUID["N"]) // 2_000_000


rule poly_jam:
    """Two-stage LS compression of the polydisperse system or one of its bi- and tridisperse equivalents."""
    output:
        "results/polydisperse/{protocol}/{family}/w{width}/seed{seed}_{system}.nc",
    params:
        checkpoint=checkpoint_beside,
        spec=lambda w: _poly_spec(w.family, w.width),
        n=lambda w: POLY_PROTOCOLS[w.protocol]["N"],
        init_phi=lambda w: POLY_PROTOCOLS[w.protocol]["init_phi"],
        growth_rate=lambda w: POLY_PROTOCOLS[w.protocol]["growth_rate"],
        switch_pressure=lambda w: POLY_PROTOCOLS[w.protocol]["switch_pressure"],
        final_growth_rate=lambda w: POLY_PROTOCOLS[w.protocol]["final_growth_rate"],
        max_pressure=lambda w: POLY_PROTOCOLS[w.protocol]["max_pressure"],
    wildcard_constraints:
        protocol="|".join(POLY_PROTOCOLS),
        family=POLY_FAMILY,
        width=POLY_WIDTH,
        system="|".join(POLY_SYSTEMS),
    threads: 1
    resources:
        mem_mb=poly_jam_mem_mb,
        runtime=poly_jam_runtime,
    log:
        "results/logs/poly_jam/{protocol}/{family}_w{width}_seed{seed}_{system}.log",
    shell:
        "hardpack eos-jam --distribution '{params.spec}' --systems {wildcards.system} --seed {wildcards.seed}"
        " --n {params.n} --init-phi {params.init_phi} --growth-rate {params.growth_rate}"
        " --switch-pressure {params.switch_pressure} --final-growth-rate {params.final_growth_rate}"
        " --max-pressure {params.max_pressure} --out {output} --checkpoint {params.checkpoint} 2> {log}"


#: summary file prefix -> (protocol folder of the runs, `hardpack eos-summary --kind`)
POLY_SUMMARIES = {"phij": ("jammed", "jam"), "crystallisation": ("crystallisation", "crystallisation")}


rule poly_jam_summary:
    """phi_J (and large-species crystallinity) over (width, system, seed) for one family: the
    equivalence runs (phij_*) or the slow runs (crystallisation_*)."""
    input:
        lambda w: _poly_jam_files(POLY_SUMMARIES[w.summary][0], w.family),
    output:
        "results/polydisperse/{summary}_{family}.nc",
    params:
        kind=lambda w: POLY_SUMMARIES[w.summary][1],
    wildcard_constraints:
        summary="|".join(POLY_SUMMARIES),
        family=POLY_FAMILY,
    log:
        "results/logs/poly_jam_summary/{summary}_{family}.log",
    shell:
        "hardpack eos-summary --kind {params.kind} {input} --out {output} 2> {log}"


rule poly_fluid:
    """Equilibrium Z(phi) of the distribution and its equivalents, against BMCSL."""
    output:
        "results/polydisperse/fluid/{family}_w{width}.nc",
    params:
        spec=lambda w: _poly_spec(w.family, w.width),
        phi=" ".join(str(p) for p in POLY_FLUID.get("phi", [])),
        n=POLY_FLUID.get("N"),
        collisions=POLY_FLUID.get("collisions"),
        seed=POLY_FLUID.get("seed"),
    wildcard_constraints:
        family=POLY_FAMILY,
        width=POLY_WIDTH,
    threads: 1
    resources:
        mem_mb=lambda w: 500 + POLY_FLUID["N"] // 5,
        runtime=poly_fluid_runtime,
    log:
        "results/logs/poly_fluid/{family}_w{width}.log",
    shell:
        "hardpack eos-fluid --distribution '{params.spec}' --systems poly bi tri --phi {params.phi}"
        " --n {params.n} --collisions {params.collisions} --seed {params.seed} --out {output} 2> {log}"


rule poly_fluid_summary:
    """All fluid cases in one Dataset (case, system, phi)."""
    input:
        [f"results/polydisperse/fluid/{family}_w{_poly_width(w)}.nc"
         for family, widths in POLY_FLUID.get("widths", {}).items() for w in widths],
    output:
        "results/polydisperse/fluid_summary.nc",
    log:
        "results/logs/poly_fluid_summary.log",
    shell:
        "hardpack eos-summary --kind fluid {input} --out {output} 2> {log}"


rule fig_phij_vs_omega:
    """phi_J vs omega (sigma) for poly / bi / tri with the published fits, and relative deviations."""
    input:
        expand("results/polydisperse/phij_{family}.nc", family=list(POLY_JAM.get("widths", {}))),
    output:
        pdf="results/figures/phij_vs_omega.pdf",
        png=report("results/figures/phij_vs_omega.png", caption="../report/polydisperse_phij.rst",
                   category="3 polydisperse"),
    log:
        "results/logs/figures/phij_vs_omega.log",
    script:
        "../scripts/plot_poly_phij.py"


rule fig_eos_vs_bmcsl:
    """Fluid Z vs phi against BMCSL (and Ogarko's Z_OL) for every distribution and its equivalents."""
    input:
        "results/polydisperse/fluid_summary.nc",
    output:
        pdf="results/figures/eos_vs_bmcsl.pdf",
        png=report("results/figures/eos_vs_bmcsl.png", caption="../report/polydisperse_eos.rst",
                   category="3 polydisperse"),
    log:
        "results/logs/figures/eos_vs_bmcsl.log",
    script:
        "../scripts/plot_poly_eos.py"


rule fig_crystallisation:
    """Slow runs: phi_J and the large-species crystallinity vs omega (uniform size)."""
    input:
        "results/polydisperse/crystallisation_uniform_size.nc",
    output:
        pdf="results/figures/crystallisation_vs_omega.pdf",
        png=report("results/figures/crystallisation_vs_omega.png",
                   caption="../report/polydisperse_crystallisation.rst", category="3 polydisperse"),
    log:
        "results/logs/figures/crystallisation_vs_omega.log",
    script:
        "../scripts/plot_poly_crystallisation.py"


if POLY_JAM.get("widths"):
    FIGURES.append("results/figures/phij_vs_omega.pdf")
    VALIDATION_INPUTS["polydisperse"] = expand("results/polydisperse/phij_{family}.nc", family=list(POLY_JAM["widths"]))
if POLY_PROTOCOLS["crystallisation"].get("widths", {}).get("uniform_size"):
    FIGURES.append("results/figures/crystallisation_vs_omega.pdf")
if POLY_PROTOCOLS["crystallisation"].get("widths"):
    VALIDATION_INPUTS.setdefault("polydisperse", []).extend(
        expand("results/polydisperse/crystallisation_{family}.nc", family=list(POLY_PROTOCOLS["crystallisation"]["widths"])))
if POLY_FLUID.get("widths"):
    FIGURES.append("results/figures/eos_vs_bmcsl.pdf")
    VALIDATION_INPUTS.setdefault("polydisperse", []).append("results/polydisperse/fluid_summary.nc")
