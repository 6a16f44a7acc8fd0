# Study 1 (SLP generator, Torquato & Jiao 2010): densest packings from N = 3^d random starts
# (Table II), MRJ-like packings beside the LS ensembles and in SLP-only systems (Table I), and the
# 3D order map phi-T over influence radii and bound widths (Fig. 6).

SLP = config.get("slp", {})
SLP_DENSEST = SLP.get("densest")
SLP_DENSEST_RUNS = {run["d"]: run for run in SLP_DENSEST["runs"]} if SLP_DENSEST else {}
if SLP_DENSEST and len(SLP_DENSEST_RUNS) != len(SLP_DENSEST["runs"]):
    raise ValueError("config: slp.densest.runs lists a dimension twice")


def slp_flags(settings):
    """The `hardpack slp` options of one (alpha, bounds) setting."""
    b = settings["bounds"]
    return (f"--alpha {settings['alpha']} --strain-bound {b['strain']} --shear-bound {b['shear']}"
            f" --displacement-bound {b['displacement']} --lp-method {settings.get('lp_method', 'highs-ipm')}")


rule slp_densest_init:
    """RSA start of N = 3^d spheres (the paper's size, or the run's own N) for one Table II run."""
    output:
        "results/slp/densest/d{d}/init_seed{seed}.nc",
    params:
        n=lambda w: SLP_DENSEST_RUNS[int(w.d)].get("N", 3 ** int(w.d)),
        phi=lambda w: SLP_DENSEST_RUNS[int(w.d)]["init_phi"],
    log:
        "results/logs/slp_densest_init/d{d}_seed{seed}.log",
    shell:
        "hardpack init --n {params.n} --d {wildcards.d} --phi {params.phi}"
        " --seed {wildcards.seed} --attr d={wildcards.d} --out {output} 2> {log}"


rule slp_densest:
    """SLP with a deforming cell from one start (Table II settings from the config)."""
    input:
        "results/slp/densest/d{d}/init_seed{seed}.nc",
    output:
        packing="results/slp/densest/d{d}/seed{seed}.nc",
        history="results/slp/densest/d{d}/history_seed{seed}.nc",
    params:
        flags=slp_flags(SLP_DENSEST) if SLP_DENSEST else "",
    threads: 1
    resources:
        mem_mb=1000,
        runtime=30,
    log:
        "results/logs/slp_densest/d{d}_seed{seed}.log",
    shell:
        "hardpack slp --init {input} --out {output.packing} --history {output.history} {params.flags}"
        " --attr d={wildcards.d} 2> {log}"


rule slp_densest_summary:
    """Table II reproduced: one Dataset over (d, seed)."""
    input:
        [f"results/slp/densest/d{d}/seed{seed}.nc" for d, run in SLP_DENSEST_RUNS.items() for seed in run["seeds"]],
    output:
        "results/slp/densest_summary.nc",
    log:
        "results/logs/slp_densest_summary.log",
    shell:
        "hardpack combine {input} --index d seed --variable n_steps --variable n_rejected"
        " --variable wall_seconds --variable cpu_seconds --variable converged --out {output} 2> {log}"


SLP_MRJ = SLP.get("mrj")
SLP_SYSTEMS = SLP_MRJ.get("systems", {}) if SLP_MRJ else {}
if SLP_MRJ:
    for _name in SLP_MRJ["ensembles"]:
        if _name not in ENSEMBLES:
            raise ValueError(f"config: slp.mrj.ensembles names {_name!r}, which is not an ensemble")
    for _name, _system in SLP_SYSTEMS.items():
        if _name in ENSEMBLES:
            raise ValueError(f"config: slp.mrj.systems.{_name} has the name of an ensemble; rename it")
        if "distribution" in _system:
            try:
                from_spec(_system["distribution"])
            except ValueError as exc:
                raise ValueError(f"config: slp.mrj.systems.{_name}.distribution: {exc}") from None
SLP_MONODISPERSE = {"kind": "monodisperse"}


def system_distribution(name):
    """Size distribution (JSON) of SLP-only system ``name``: its own or monodisperse."""
    return json.dumps(SLP_SYSTEMS[name].get("distribution", SLP_MONODISPERSE))


wildcard_constraints:
    system="[A-Za-z][A-Za-z0-9_]*",
    d=r"\d+",
    k=r"\d+",
    r=r"\d+",


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
        flags=slp_flags(SLP_MRJ) if SLP_MRJ else "",
        checkpoint="results/ensembles/{ensemble}/slp/checkpoint_seed{seed}.ckpt",  # a killed job resumes
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    log:
        "results/logs/slp_mrj/{ensemble}_seed{seed}.log",
    shell:
        "hardpack slp --init {input} --out {output.packing} --history {output.history} {params.flags}"
        " --checkpoint {params.checkpoint} 2> {log}"


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
        "hardpack combine {input} --index seed --variable n_steps --variable wall_seconds --variable cpu_seconds"
        " --attr ensemble={wildcards.ensemble} --attr distribution='{params.distribution}' --out {output} 2> {log}"


rule slp_system_init:
    """Dilute RSA start of an SLP-only Table I system (a dimension or size distribution without LS
    ensemble, e.g. the 2D polydisperse disks of Torquato & Jiao 2010, Sec. V.A)."""
    output:
        "results/slp/mrj/{system}/init_seed{seed}.nc",
    params:
        n=lambda w: SLP_SYSTEMS[w.system]["N"],
        d=lambda w: SLP_SYSTEMS[w.system]["d"],
        phi=SLP_MRJ["init_phi"] if SLP_MRJ else None,
        distribution=lambda w: system_distribution(w.system),
    log:
        "results/logs/slp_system_init/{system}_seed{seed}.log",
    shell:
        "hardpack init --n {params.n} --d {params.d} --phi {params.phi} --seed {wildcards.seed}"
        " --distribution '{params.distribution}' --attr ensemble={wildcards.system} --out {output} 2> {log}"


rule slp_system:
    """SLP (Table I settings) of one SLP-only system."""
    input:
        "results/slp/mrj/{system}/init_seed{seed}.nc",
    output:
        packing="results/slp/mrj/{system}/seed{seed}.nc",
        history="results/slp/mrj/{system}/history_seed{seed}.nc",
    params:
        flags=slp_flags(SLP_MRJ) if SLP_MRJ else "",
        checkpoint="results/slp/mrj/{system}/checkpoint_seed{seed}.ckpt",  # a killed job resumes
    threads: 1
    resources:
        mem_mb=2000,
        runtime=180,  # minutes; 3D N = 2000 (not in the default study): 1.3 CPU-h for 520 LPs, not converged
    log:
        "results/logs/slp_system/{system}_seed{seed}.log",
    shell:
        "hardpack slp --init {input} --out {output.packing} --history {output.history} {params.flags}"
        " --checkpoint {params.checkpoint} 2> {log}"


rule verify_slp_system:
    """LP jamming tests of one SLP-only packing, by sequential loading (see verify_jamming_slp)."""
    input:
        "results/slp/mrj/{system}/seed{seed}.nc",
    output:
        "results/slp/mrj/{system}/jamming_seed{seed}.nc",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=20,
    log:
        "results/logs/verify_slp_system/{system}_seed{seed}.log",
    shell:
        "hardpack verify {input} --out {output} --seed {wildcards.seed} --method sequential > {log} 2>&1"


rule slp_system_summary:
    """Densities (kind=slp) or jamming verdicts (kind=slp_jamming) of an SLP-only system over its seeds."""
    input:
        lambda w: expand("results/slp/mrj/{system}/{prefix}seed{seed}.nc", system=w.system,
                         prefix="" if w.kind == "slp" else "jamming_", seed=SLP_SYSTEMS[w.system]["seeds"]),
    output:
        "results/slp/mrj/{system}/{kind}_summary.nc",
    wildcard_constraints:
        kind="slp|slp_jamming",
    params:
        variables=lambda w: ("--variable n_steps --variable wall_seconds --variable cpu_seconds" if w.kind == "slp" else
                             "--variable z_mean --variable rattler_fraction --variable isostaticity_gap"
                             " --variable local --variable collective --variable strict"),
        distribution=lambda w: system_distribution(w.system),
    log:
        "results/logs/slp_system_summary/{system}_{kind}.log",
    shell:
        "hardpack combine {input} --index seed {params.variables} --attr ensemble={wildcards.system}"
        " --attr distribution='{params.distribution}' --out {output} 2> {log}"


SLP_DILUTED = SLP.get("diluted")
if SLP_DILUTED:
    if not SLP_MRJ or SLP_DILUTED["ensemble"] not in SLP_MRJ["ensembles"]:
        raise ValueError(f"config: slp.diluted.ensemble {SLP_DILUTED['ensemble']!r} must be one of "
                         "slp.mrj.ensembles (its SLP MRJ packings are the starts)")
    _missing = set(SLP_DILUTED["seeds"]) - set(ENSEMBLES[SLP_DILUTED["ensemble"]]["seeds"])
    if _missing:
        raise ValueError(f"config: slp.diluted.seeds {sorted(_missing)} are not seeds of ensemble "
                         f"{SLP_DILUTED['ensemble']!r}")
SLP_DILUTED_ROUNDS = range(1, SLP_DILUTED["rounds"] + 1) if SLP_DILUTED else []


rule slp_diluted:
    """Torquato & Jiao 2010, Sec. VI: remove a fraction of the spheres of one SLP MRJ packing at
    random, re-jam by SLP (the Table I settings), repeat; one packing per round."""
    input:
        "results/ensembles/{ensemble}/slp/seed{seed}.nc",
    output:
        expand("results/slp/diluted/{{ensemble}}/seed{{seed}}/round{r}.nc", r=SLP_DILUTED_ROUNDS),
    params:
        flags=slp_flags(SLP_MRJ) if SLP_DILUTED else "",
        fraction=SLP_DILUTED["fraction"] if SLP_DILUTED else None,
        rounds=SLP_DILUTED["rounds"] if SLP_DILUTED else None,
        out_dir="results/slp/diluted/{ensemble}/seed{seed}",
        checkpoint="results/slp/diluted/{ensemble}/checkpoint_seed{seed}.ckpt",  # a killed job resumes
    threads: 1
    resources:
        mem_mb=2000,
        runtime=360,  # minutes; N = 1000: ~12 CPU-min per round
    log:
        "results/logs/slp_diluted/{ensemble}_seed{seed}.log",
    shell:
        "hardpack slp-dilute --init {input} --out-dir {params.out_dir} --fraction {params.fraction}"
        " --rounds {params.rounds} --seed {wildcards.seed} {params.flags} --checkpoint {params.checkpoint} 2> {log}"


rule verify_slp_diluted:
    """LP jamming tests of one diluted-MRJ packing, by sequential loading (see verify_jamming_slp)."""
    input:
        "results/slp/diluted/{ensemble}/seed{seed}/round{r}.nc",
    output:
        "results/slp/diluted/{ensemble}/seed{seed}/jamming_round{r}.nc",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        checkpoint=checkpoint_beside,
    log:
        "results/logs/verify_slp_diluted/{ensemble}_seed{seed}_round{r}.log",
    shell:
        "hardpack verify {input} --out {output} --seed {wildcards.seed} --method sequential"
        " --checkpoint {params.checkpoint} > {log} 2>&1"


def slp_diluted_files(prefix):
    """The MRJ start (round 0) and every round of every diluted seed: packings ('') or verdicts ('jamming_')."""
    ensemble = SLP_DILUTED["ensemble"]
    start = "results/ensembles/{e}/slp{j}/seed{s}.nc".format
    return [path for seed in SLP_DILUTED["seeds"] for path in (
        [start(e=ensemble, j="_jamming" if prefix else "", s=seed)]
        + [f"results/slp/diluted/{ensemble}/seed{seed}/{prefix}round{r}.nc" for r in SLP_DILUTED_ROUNDS])]


rule slp_diluted_summary:
    """phi, phi without rattlers, backbone Z, verdicts and T of every diluted-MRJ round, over (seed, round)."""
    input:
        packings=slp_diluted_files("") if SLP_DILUTED else [],
        verdicts=slp_diluted_files("jamming_") if SLP_DILUTED else [],
    output:
        "results/slp/diluted_summary.nc",
    log:
        "results/logs/slp_diluted_summary.log",
    script:
        "../scripts/slp_diluted_summary.py"


SLP_ORDER = SLP.get("order_map")


def order_map_n(k):
    """Cell size N of order-map setting k: its own ``N`` or the map's default."""
    return SLP_ORDER["settings"][int(k)].get("N", SLP_ORDER["N"])


rule slp_order_map_init:
    """Dilute 3D monodisperse start of N spheres, shared by every setting of that N."""
    output:
        "results/slp/order_map/init_n{n}_seed{seed}.nc",
    params:
        phi=SLP_ORDER["init_phi"] if SLP_ORDER else None,
    log:
        "results/logs/slp_order_map_init/n{n}_seed{seed}.log",
    shell:
        "hardpack init --n {wildcards.n} --d 3 --phi {params.phi} --seed {wildcards.seed} --out {output} 2> {log}"


rule slp_order_map_run:
    """SLP from one start with setting k of slp.order_map.settings."""
    input:
        lambda w: f"results/slp/order_map/init_n{order_map_n(w.k)}_seed{w.seed}.nc",
    output:
        "results/slp/order_map/s{k}_seed{seed}.nc",
    params:
        flags=lambda w: slp_flags(SLP_ORDER["settings"][int(w.k)]),
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    log:
        "results/logs/slp_order_map/s{k}_seed{seed}.log",
    shell:
        "hardpack slp --init {input} --out {output} {params.flags} --attr setting={wildcards.k} 2> {log}"


rule verify_slp_order_map:
    """Strict-jamming verdict of one order-map packing, by sequential loading (see verify_jamming_slp)."""
    input:
        "results/slp/order_map/s{k}_seed{seed}.nc",
    output:
        "results/slp/order_map/jamming_s{k}_seed{seed}.nc",
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        "results/logs/verify_slp_order_map/s{k}_seed{seed}.log",
    shell:
        "hardpack verify {input} --out {output} --seed {wildcards.seed} --method sequential > {log} 2>&1"


SLP_ORDER_RUNS = ([(k, seed) for k in range(len(SLP_ORDER["settings"])) for seed in SLP_ORDER["seeds"]]
                  if SLP_ORDER else [])


rule slp_order_map_summary:
    """phi, translational order T, jamming verdict and settings of every order-map packing."""
    input:
        packings=[f"results/slp/order_map/s{k}_seed{seed}.nc" for k, seed in SLP_ORDER_RUNS],
        verdicts=[f"results/slp/order_map/jamming_s{k}_seed{seed}.nc" for k, seed in SLP_ORDER_RUNS],
    output:
        "results/slp/order_map_summary.nc",
    log:
        "results/logs/slp_order_map_summary.log",
    script:
        "../scripts/slp_order_map.py"


rule fig_slp_densest:
    """Table II: SLP densities from N = 3^d starts against the densest known packings."""
    input:
        "results/slp/densest_summary.nc",
    output:
        pdf="results/figures/slp_densest.pdf",
        png=report("results/figures/slp_densest.png", caption="../report/slp_densest.rst", category="6 SLP"),
    log:
        "results/logs/figures/slp_densest.log",
    script:
        "../scripts/plot_slp_densest.py"


rule fig_slp_vs_ls:
    """Table I: SLP and LS jamming densities of the same ensembles, beside the published values."""
    input:
        slp=expand("results/ensembles/{ensemble}/slp_summary.nc", ensemble=SLP_MRJ["ensembles"]) if SLP_MRJ else [],
        ls=expand("results/ensembles/{ensemble}/jammed_summary.nc", ensemble=SLP_MRJ["ensembles"]) if SLP_MRJ else [],
        systems=expand("results/slp/mrj/{system}/slp_summary.nc", system=SLP_SYSTEMS),
    output:
        pdf="results/figures/slp_vs_ls.pdf",
        png=report("results/figures/slp_vs_ls.png", caption="../report/slp_vs_ls.rst", category="6 SLP"),
    log:
        "results/logs/figures/slp_vs_ls.log",
    script:
        "../scripts/plot_slp_vs_ls.py"


rule fig_slp_order_map:
    """Fig. 6: translational order T against phi of the SLP order-map and diluted-MRJ packings."""
    input:
        order_map=["results/slp/order_map_summary.nc"] if SLP_ORDER else [],
        diluted=["results/slp/diluted_summary.nc"] if SLP_DILUTED else [],
    output:
        pdf="results/figures/slp_order_map.pdf",
        png=report("results/figures/slp_order_map.png", caption="../report/slp_order_map.rst", category="6 SLP"),
    log:
        "results/logs/figures/slp_order_map.log",
    script:
        "../scripts/plot_slp_order_map.py"


if SLP_DENSEST:
    FIGURES.append("results/figures/slp_densest.pdf")
    VALIDATION_INPUTS["slp_densest"] = ["results/slp/densest_summary.nc"]
if SLP_MRJ:
    FIGURES.append("results/figures/slp_vs_ls.pdf")
    VALIDATION_INPUTS["slp_mrj"] = (
        expand("results/ensembles/{ensemble}/slp_summary.nc", ensemble=SLP_MRJ["ensembles"])
        + expand("results/slp/mrj/{system}/slp_summary.nc", system=SLP_SYSTEMS))
    VALIDATION_INPUTS["slp_jamming"] = (
        expand("results/ensembles/{ensemble}/slp_jamming_summary.nc", ensemble=SLP_MRJ["ensembles"])
        + expand("results/slp/mrj/{system}/slp_jamming_summary.nc", system=SLP_SYSTEMS))
if SLP_ORDER:
    VALIDATION_INPUTS["slp_order_map"] = ["results/slp/order_map_summary.nc"]
if SLP_DILUTED:
    VALIDATION_INPUTS["slp_diluted"] = ["results/slp/diluted_summary.nc"]
if SLP_ORDER or SLP_DILUTED:  # the diluted-MRJ summary is built for this figure
    FIGURES.append("results/figures/slp_order_map.pdf")
