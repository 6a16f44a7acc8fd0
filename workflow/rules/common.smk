# Everything of the workflow that is not a rule: the config checks, the systems of every study
# (parsed from the config once), the input and parameter functions, the summaries, and the final
# outputs of the workflow (final_outputs(), figures(), validation_inputs()). The rule files hold
# rules only and read what they need from here.
#
# One results layout, by study (a generator or an analysis) and system name:
#   results/{study}/{name}/{step}/seed{seed}.nc     one file per seed and step (init, jammed, slp, verdict, ...)
#   results/{study}/{name}/{step}_summary.nc        a step over the seeds of one system
#   results/{study}/{step}_summary.nc               a step over the systems of a study
#   results/figures/{figure}.pdf|png, results/validation/
#   results/logs/{rule}/{wildcards}.log             stdout and stderr of each job
#   results/benchmarks/{rule}/{wildcards}.tsv       time and memory of each job (benchmarks/pipeline_times.py)
# A file's ensemble name is in its `ensemble` attribute; nothing reads it from the path.

import json
import math
import os
import re
import shlex

from hardpack.config import check_config, validate_schema


validate_schema(config, os.path.join(workflow.basedir, "workflow", "schemas", "config.schema.yaml"))


wildcard_constraints:
    study=r"[a-z][a-z_]*",
    name=r"[A-Za-z][A-Za-z0-9_.]*",
    ensemble=r"[A-Za-z][A-Za-z0-9_]*",
    seed=r"\d+",
    reps=r"\d+",
    phi=r"[0-9.]+",


ENSEMBLES = config["ensembles"]
SLP = config.get("slp", {})
SLP_MRJ = SLP.get("mrj")
SLP_DILUTED = SLP.get("diluted")
SLP_DENSEST = SLP.get("densest")
SLP_ORDER = SLP.get("order_map")
RATES = config.get("rates")
FREEENERGY = config.get("freeenergy")
POLY = config.get("polydisperse", {})
GLASS = config.get("glass")
MICROSEG = config.get("microsegregated")
ELLIPSOIDS = config.get("ellipsoids")
ELLIPSOID_CRYSTALS = config.get("ellipsoid_crystals")
CRYSTAL_SEARCH = (ELLIPSOID_CRYSTALS or {}).get("search")
CONTAINERS = config.get("containers")
ELLIPSOID_CONTAINERS = config.get("ellipsoid_containers")
STRICT_LS = config.get("strict_ls")
LS_DENSEST = config.get("ls_densest")
VALIDATION = config.get("validation", {})
MONODISPERSE = {"kind": "monodisperse"}


# Config checks the JSON schema cannot express (cross references); each names the key to fix.
check_config(config)


# ---------------------------------------------------------------------------------------------
# The systems of the packing studies: SYSTEMS[study][name] holds what the generic jobs of a
# system need (N, d, seeds, the start packing, init and generator options, `--attr` attributes).
#   ls             LS ensembles (config ensembles): init -> jammed (+ timeseries) -> verdict -> structure
#   ls_rates       the growth-rate scan, single-stage LS from an ensemble's starts
#   slp_mrj        SLP MRJ packings beside LS ensembles and of the SLP-only systems (Table I)
#   slp_densest    SLP from N = 3^d starts (Table II), names d{d}
#   ls_densest     LS from N = 3^d starts (Table II, LS column), names d{d}
#   slp_order_map  starts n{N}, one SLP run per setting s{k} (Fig. 6)
#   slp_diluted    diluted-MRJ rounds from an ensemble's SLP MRJ packings (Sec. VI)
#   ellipsoids     LS packings of ellipsoids {family}_a{alpha} and binary ellipses ellipses_a{alpha}
#                  (Donev 2006, Sec. 5.2): init -> jammed (+ timeseries) -> contacts

def slp_flags(settings):
    """The `hardpack slp` options of one (alpha, bounds) setting."""
    b = settings["bounds"]
    return (f"--alpha {settings['alpha']} --strain-bound {b['strain']} --shear-bound {b['shear']}"
            f" --displacement-bound {b['displacement']} --lp-method {settings.get('lp_method', 'highs-ipm')}")


def _ls_compress(ens):
    final = (f" --final-growth-rate {ens['final_growth_rate']} --switch-pressure {ens['switch_pressure']}"
             if "final_growth_rate" in ens else "")
    return f"--growth-rate {ens['growth_rate']}{final} --max-pressure {ens['max_pressure']} --contact-forces"


def _system(n, d, seeds, init_phi=None, distribution=MONODISPERSE, **extra):
    return dict(N=n, d=d, seeds=list(seeds), init_phi=init_phi, distribution=distribution, **extra)


def order_map_n(k):
    """Cell size N of order-map setting k: its own ``N`` or the map's default."""
    return SLP_ORDER["settings"][k].get("N", SLP_ORDER["N"])


def _systems():
    systems = {"ls": {}, "ls_rates": {}, "slp_mrj": {}, "slp_densest": {}, "slp_order_map": {}, "slp_diluted": {}}
    for name, ens in ENSEMBLES.items():
        systems["ls"][name] = _system(ens["N"], ens["d"], ens["seeds"], ens["init_phi"], ens["distribution"],
                                      attrs={"ensemble": name}, compress=_ls_compress(ens))
    if RATES:
        name, ens = RATES["ensemble"], ENSEMBLES[RATES["ensemble"]]
        for gamma in RATES["growth_rates"]:
            systems["ls_rates"][f"{name}_gamma{gamma}"] = _system(
                ens["N"], ens["d"], RATES["seeds"], start=f"results/ls/{name}/init/seed{{seed}}.nc",
                compress=f"--growth-rate {gamma} --max-pressure {ens['max_pressure']}")
    if SLP_MRJ:
        for name in SLP_MRJ["ensembles"]:
            ens = ENSEMBLES[name]
            systems["slp_mrj"][name] = _system(ens["N"], ens["d"], ens["seeds"], SLP_MRJ["init_phi"],
                                               ens["distribution"], attrs={"ensemble": name},
                                               slp=slp_flags(SLP_MRJ))
        for name, spec in SLP_MRJ.get("systems", {}).items():
            # 3D N = 2000 (not in the default study): 1.3 CPU-h for 520 LPs, not converged
            systems["slp_mrj"][name] = _system(spec["N"], spec["d"], spec["seeds"], SLP_MRJ["init_phi"],
                                               spec.get("distribution", MONODISPERSE), attrs={"ensemble": name},
                                               slp=slp_flags(SLP_MRJ))
    if SLP_DENSEST:
        for run in SLP_DENSEST["runs"]:
            d = run["d"]
            systems["slp_densest"][f"d{d}"] = _system(run.get("N", 3**d), d, run["seeds"], run["init_phi"],
                                                      attrs={"d": d}, slp=slp_flags(SLP_DENSEST))
    if SLP_ORDER:
        for k, setting in enumerate(SLP_ORDER["settings"]):
            n = order_map_n(k)
            systems["slp_order_map"][f"n{n}"] = _system(n, 3, SLP_ORDER["seeds"], SLP_ORDER["init_phi"], attrs={})
            systems["slp_order_map"][f"s{k}"] = _system(
                n, 3, SLP_ORDER["seeds"], start=f"results/slp_order_map/n{n}/init/seed{{seed}}.nc",
                attrs={"setting": k}, slp=slp_flags(setting))
    if SLP_DILUTED:
        name, ens = SLP_DILUTED["ensemble"], ENSEMBLES[SLP_DILUTED["ensemble"]]
        systems["slp_diluted"][name] = _system(
            ens["N"], ens["d"], SLP_DILUTED["seeds"], start=f"results/slp_mrj/{name}/slp/seed{{seed}}.nc",
            rounds=SLP_DILUTED["rounds"], slp=slp_flags(SLP_MRJ),
            dilute=f"--fraction {SLP_DILUTED['fraction']} --rounds {SLP_DILUTED['rounds']}")
    systems["ellipsoids"] = _ellipsoid_systems()
    systems["containers"] = _container_systems()
    systems["ellipsoid_containers"] = _ellipsoid_container_systems()
    systems["strict_ls"] = _strict_ls_systems()
    systems["ls_densest"] = _ls_densest_systems()
    return systems


def _ls_densest_systems():
    """LS from N = 3^d equal spheres (Torquato & Jiao 2010, Table II, LS column), one system d{d} per
    run: one growth rate to max_pressure, in a deforming cell where the run says so."""
    if not LS_DENSEST:
        return {}
    systems = {}
    for run in LS_DENSEST["runs"]:
        compress = f"--growth-rate {run['growth_rate']} --max-pressure {LS_DENSEST['max_pressure']}"
        compress += " --deforming-cell" if run.get("deforming_cell") else ""
        systems[f"d{run['d']}"] = _system(run.get("N", 3 ** run["d"]), run["d"], run["seeds"], run["init_phi"],
                                          attrs={}, compress=compress, deforming=bool(run.get("deforming_cell")))
    return systems


def _strict_ls_systems():
    """Monodisperse LS packings grown in a deforming periodic cell, one system d{d} per dimension
    (Donev 2006, Sec. 4.7.2.3 and Fig. 4.15): the LS two-stage protocol with `--deforming-cell`."""
    if not STRICT_LS:
        return {}
    c = STRICT_LS
    compress = (f"--growth-rate {c['growth_rate']} --final-growth-rate {c['final_growth_rate']}"
                f" --switch-pressure {c['switch_pressure']} --max-pressure {c['max_pressure']} --deforming-cell")
    return {f"d{spec['d']}": _system(spec["N"], spec["d"], spec["seeds"], c["init_phi"],
                                     attrs={"ensemble": f"strict_ls_d{spec['d']}"}, compress=compress,
                                     deforming=True)
            for spec in c["systems"]}


def _container_systems():
    """Spheres grown to jamming in spherical containers, one system n{N} per container size
    (Donev 2006, Sec. 7.3): the LS ensembles' two-stage protocol without contact forces (the
    engine logs no wall forces)."""
    if not CONTAINERS:
        return {}
    c = CONTAINERS
    compress = (f"--growth-rate {c['growth_rate']} --final-growth-rate {c['final_growth_rate']}"
                f" --switch-pressure {c['switch_pressure']} --max-pressure {c['max_pressure']}")
    systems = {f"n{n}": _system(n, 3, c["seeds"], c["init_phi"], attrs={}, compress=compress,
                                boundary="spherical_container") for n in c["N"]}
    systems["bulk"] = _system(c["bulk"]["N"], 3, c["bulk"]["seeds"], c["init_phi"], attrs={}, compress=compress,
                              boundary="periodic")
    return systems


def _ellipsoid_container_systems():
    """Ellipsoids grown to jamming in spherical containers, one system {shape}_n{N} per shape and
    container size (Donev 2006, Sec. 7.3.2.1): a dilute start inside the container, the two-stage
    protocol."""
    if not ELLIPSOID_CONTAINERS:
        return {}
    c = ELLIPSOID_CONTAINERS
    compress = (f"--growth-rate {c['growth_rate']} --final-growth-rate {c['final_growth_rate']}"
                f" --switch-pressure {c['switch_pressure']} --max-pressure {c['max_pressure']}")
    return {f"{shape}_n{n}": _system(n, 3, c["seeds"], c["init_phi"], attrs={"shape_name": shape},
                                     compress=compress, semiaxes=list(axes), boundary="spherical_container")
            for shape, axes in c["shapes"].items() for n in c["N"]}


def ellipsoid_container_files(shape, step):
    """Per-seed files of every container size of one shape
    (results/ellipsoid_containers/{shape}_n{N}/{step}/seed{seed}.nc)."""
    return [path for name, s in SYSTEMS["ellipsoid_containers"].items() if s["attrs"]["shape_name"] == shape
            for path in seed_files("ellipsoid_containers", name, step)]


def container_files(step):
    """Per-seed files of every container size (results/containers/n{N}/{step}/seed{seed}.nc)."""
    return [path for name, s in SYSTEMS["containers"].items() if s["boundary"] == "spherical_container"
            for path in seed_files("containers", name, step)]


def container_bulk_packings():
    """The periodic packings of the containers' protocol (results/containers/bulk/jammed/seed{seed}.nc)."""
    return seed_files("containers", "bulk", "jammed")


def window_packings():
    """The periodic LS packings of the window study (Donev 2006, Fig. 7.3)."""
    return seed_files("ls", CONTAINERS["windows"]["ensemble"], "jammed")


def _ellipsoid_shapes():
    """(family, beta, alpha) of every 3D ellipsoid system: semiaxes 1 : alpha^beta : alpha."""
    shapes = [(family, beta, alpha) for family, beta in ELLIPSOIDS["families"].items()
              for alpha in ELLIPSOIDS["alphas"]]
    if "mm" in ELLIPSOIDS:
        family = ELLIPSOIDS["mm"]["family"]
        shapes.append((family, ELLIPSOIDS["families"][family], ELLIPSOIDS["mm"]["alpha"]))
    return list(dict.fromkeys(shapes))


def _ellipsoid_systems():
    if not ELLIPSOIDS:
        return {}
    e = ELLIPSOIDS

    def compress_options(final_rate):
        return (f"--growth-rate {e['growth_rate']} --final-growth-rate {final_rate}"
                f" --switch-pressure {e['switch_pressure']} --max-pressure {e['max_pressure']}")

    compress = compress_options(e["final_growth_rate"])
    systems = {}
    for family, beta, alpha in _ellipsoid_shapes():
        systems[f"{family}_a{alpha:g}"] = _system(
            e["N"], 3, e["seeds"], e["init_phi"], attrs={"family": family, "beta": beta, "alpha": alpha},
            semiaxes=[1.0, alpha**beta, alpha], compress=compress)
    near = e.get("near_sphere")
    near_compress = compress_options(near.get("final_growth_rate", e["final_growth_rate"])) if near else ""
    for family in near["families"] if near else []:
        beta = e["families"][family]
        for alpha in near["alphas"]:
            systems[f"near_{family}_a{alpha:g}"] = _system(
                near["N"], 3, near["seeds"], e["init_phi"],
                attrs={"family": family, "beta": beta, "alpha": alpha, "part": "near_sphere"},
                semiaxes=[1.0, alpha**beta, alpha], compress=near_compress, near_sphere=True)
    ell = e.get("ellipses")
    for alpha in ell["alphas"] if ell else []:
        sizes = {"kind": "bidisperse", "size_ratio": ell["size_ratio"], "large_fraction": ell["large_fraction"]}
        systems[f"ellipses_a{alpha:g}"] = _system(
            ell["N"], 2, ell["seeds"], e["init_phi"], sizes, attrs={"family": "ellipses", "beta": 1.0, "alpha": alpha},
            semiaxes=[1.0, alpha], compress=compress)
    return systems


def ellipsoid_files(dim, step, near_sphere=False):
    """Per-seed files of every ellipsoid (dim 3) or ellipse (dim 2) system of the shape grid, or of
    the near-sphere systems."""
    return [path for name, spec in SYSTEMS["ellipsoids"].items()
            if spec["d"] == dim and spec.get("near_sphere", False) == near_sphere
            for path in seed_files("ellipsoids", name, step)]


def mm_system():
    """The name of the M&M-shaped ellipsoid system (Donev 2006, Fig. 5.1)."""
    return f"{ELLIPSOIDS['mm']['family']}_a{ELLIPSOIDS['mm']['alpha']:g}"


def init_shape(wildcards):
    """`hardpack init --semiaxes` of an ellipsoid system (empty for spheres)."""
    semiaxes = system(wildcards).get("semiaxes")
    return "--semiaxes " + " ".join(f"{a:.17g}" for a in semiaxes) if semiaxes else ""


SYSTEMS = _systems()
#: the packing step each study's verdicts judge
PACKED = {"ls": "jammed", "slp_mrj": "slp", "slp_order_map": "slp", "slp_diluted": "slp", "strict_ls": "jammed"}


def system(wildcards):
    """The spec of the system {study}/{name} of a job."""
    return SYSTEMS[wildcards.study][wildcards.name]


def seed_files(study, name, step):
    """One file per seed of a system: results/{study}/{name}/{step}/seed{seed}.nc."""
    return [f"results/{study}/{name}/{step}/seed{seed}.nc" for seed in SYSTEMS[study][name]["seeds"]]


def attr_options(attrs):
    """`--attr KEY=VALUE` options, quoted for the shell."""
    return " ".join(f"--attr {shlex.quote(f'{key}={value}')}" for key, value in attrs.items())


def start_packing(wildcards):
    """The packing a generator job starts from: the system's own init file unless it names another."""
    start = system(wildcards).get("start", f"results/{wildcards.study}/{wildcards.name}/init/seed{{seed}}.nc")
    return start.format(seed=wildcards.seed)


def packed_file(wildcards):
    """The packing a verdict judges: results/{study}/{name}/{packed step}/{sample}.nc."""
    return f"results/{wildcards.study}/{wildcards.name}/{PACKED[wildcards.study]}/{wildcards.sample}.nc"


def sample_seed(wildcards):
    """The seed of a sample (seed{seed} or seed{seed}/round{r})."""
    return int(re.match(r"seed(\d+)", wildcards.sample).group(1))


def checkpoint_beside(wildcards, output):
    """params function: the checkpoint of a resumable job, beside its first output (.nc -> .ckpt);
    a killed job started again resumes from it, and the job removes it when it succeeds."""
    return output[0].removesuffix(".nc") + ".ckpt"


def checkpoint_option(wildcards, output):
    """params function: `--checkpoint PATH` (:func:`checkpoint_beside`) for a compression that can
    resume, nothing for a deforming-cell one (short runs of small systems; the engine has no
    checkpoints)."""
    if system(wildcards).get("deforming"):
        return ""
    return f"--checkpoint {checkpoint_beside(wildcards, output)}"


def diluted_rounds(name):
    return range(1, SYSTEMS["slp_diluted"][name]["rounds"] + 1)


def diluted_files(name, step):
    """The MRJ start (round 0) and every round of every diluted seed: packings (step 'slp') or
    their verdicts (step 'verdict')."""
    return [path for seed in SYSTEMS["slp_diluted"][name]["seeds"] for path in (
        [f"results/slp_mrj/{name}/{step}/seed{seed}.nc"]
        + [f"results/slp_diluted/{name}/{step}/seed{seed}/round{r}.nc" for r in diluted_rounds(name)])]


def order_map_files(step):
    """Files of every order-map run (setting s{k}), in setting order."""
    return [path for name, spec in SYSTEMS["slp_order_map"].items() if "slp" in spec
            for path in seed_files("slp_order_map", name, step)]


# ---------------------------------------------------------------------------------------------
# Free energies (BCMD, Donev, Stillinger & Torquato 2007) and the polydisperse study (Ogarko ch. 3).

PHI_CP = math.pi / math.sqrt(18)


def fcc_dmu_max(phi):
    """Initial cell size: the paper's 1 at melting, 10 disjoint-cell points near jamming."""
    return min(1.0, 10.0 * ((PHI_CP / float(phi)) ** (1 / 3) - 1))


def bcmd_options(wildcards):
    """`hardpack bcmd` size options of an FCC condition: the melting density (phi = 0.545), the
    jamming limit (delta = 1e-6), or one density phi{phi} of the free energy vs density."""
    if wildcards.condition == "melting":
        return "--phi 0.545 --dmu-max 1 --theta 1"
    if wildcards.condition == "jamming":
        return "--delta 1e-6 --dmu-max 1e-5 --theta 0.5"
    phi = wildcards.condition.removeprefix("phi")
    return f"--phi {phi} --dmu-max {fcc_dmu_max(phi)} --theta 1"


def bcmd_files(condition):
    if condition in ("melting", "jamming"):
        return [f"results/bcmd_fcc/reps{reps}/{condition}/seed{seed}.nc"
                for reps in FREEENERGY["fcc_reps"] for seed in FREEENERGY["seeds"]]
    dens = FREEENERGY["density"]
    if condition == "density":
        return [f"results/bcmd_fcc/reps{dens['reps']}/phi{phi}/seed{seed}.nc"
                for phi in dens["phi"] for seed in dens["seeds"]]
    return [f"results/bcmd_fcc/reps{dens['reps']}/eos/phi{phi}.nc" for phi in dens["phi"]]


def ellipse_bcmd_files():
    """One isostatic alpha = 2 ellipse packing per seed (Donev 2006, sec. 6.4.3)."""
    return [f"results/bcmd_ellipse/seed{seed}/bcmd.nc" for seed in FREEENERGY["ellipse"]["seeds"]]


def simplex_files(ensemble):
    return [f"results/bcmd_simplex/{ensemble}/{frozen}/seed{seed}.nc"
            for seed in FREEENERGY["simplex"]["seeds"] for frozen in ("particle", "cm")]


#: jam protocols of the polydisperse study by study name: the equivalence runs and the slow
#: crystallisation runs, and their `hardpack poly-summary --kind`
POLY_PROTOCOLS = {"phij": POLY.get("jam", {}), "crystallisation": POLY.get("crystallisation", {})}
POLY_SUMMARY_KIND = {"phij": "jam", "crystallisation": "crystallisation"}
POLY_FLUID = POLY.get("fluid", {})
POLY_SYSTEMS = ["poly", "bi", "tri"]
POLY_WIDTH_NAME = {"uniform_size": "omega", "uniform_volume": "omega", "lognormal": "sigma"}
POLY_FAMILY = "uniform_size|uniform_volume|lognormal"
POLY_WIDTH = r"[0-9]+(\.[0-9]+)?"


def poly_width(value):
    return f"{float(value):g}"


def poly_spec(wildcards):
    """The size distribution (JSON) of a polydisperse case {family}_w{width}."""
    return json.dumps({"kind": wildcards.family, POLY_WIDTH_NAME[wildcards.family]: float(wildcards.width)})


def poly_protocol(wildcards):
    return POLY_PROTOCOLS[wildcards.protocol]


def poly_jam_files(protocol, family):
    runs = POLY_PROTOCOLS[protocol]
    return [f"results/poly_{protocol}/{family}_w{poly_width(w)}/{member}/seed{seed}.nc"
            for w in runs["widths"][family] for seed in runs["seeds"] for member in POLY_SYSTEMS]



# ---------------------------------------------------------------------------------------------
# Binary hard-disk glasses (Donev 2006, ch. 13). Systems: the mixture `binary`, monodisperse
# disks `mono`, and the mixtures at x_large -+ dx (`binary_xm`, `binary_xp`: x_A + dx and x_A - dx)
# for mu~_B. A compression runs in stages through its snapshot densities, each stage a
# `hardpack compress` from the previous stage's packing:
#   results/glass/{system}/g{rate}/phi{phi}/seed{seed}.nc (+ ts_seed{seed}.nc, its time series)
# The optional slow branch (glass.slow) of `binary` and `mono` starts from the slowest of
# glass.rates at its from_phi snapshot and has only the stages above it.

GLASS_SLOW = (GLASS or {}).get("slow")


def _glass_systems():
    if not GLASS:
        return {}
    x, dx = GLASS["x_large"], GLASS["composition"]["dx"]
    comp = GLASS["composition"]
    rates = GLASS["rates"] + ([GLASS_SLOW["rate"]] if GLASS_SLOW else [])
    full = dict(rates=rates, stages=sorted(GLASS["snapshots"]) + [GLASS["phi_end"]])
    return {
        "binary": dict(kappa=GLASS["kappa"], x=x, **full),
        "mono": dict(kappa=1.0, x=0.0, **full),
        "binary_xm": dict(kappa=GLASS["kappa"], x=x - dx, rates=[comp["rate"]], stages=[comp["phi_end"]]),
        "binary_xp": dict(kappa=GLASS["kappa"], x=x + dx, rates=[comp["rate"]], stages=[comp["phi_end"]]),
    }


GLASS_SYSTEMS = _glass_systems()


def glass_distribution(wildcards):
    spec = GLASS_SYSTEMS[wildcards.system]
    if spec["x"] == 0.0:
        return json.dumps({"kind": "monodisperse"})
    return json.dumps({"kind": "bidisperse", "size_ratio": spec["kappa"], "large_fraction": spec["x"]})


def glass_stages(system, rate):
    """The stage densities of a compression at ``rate`` (the slow branch: those above its from_phi)."""
    stages = GLASS_SYSTEMS[system]["stages"]
    if GLASS_SLOW and float(rate) == GLASS_SLOW["rate"]:
        return [p for p in stages if p > GLASS_SLOW["from_phi"]]
    return stages


def glass_snapshot(system, rate, phi, seed):
    """The packing of the compression at ``rate`` at ``phi``; the slow branch's snapshots at or
    below its from_phi are those of the slowest of glass.rates, where it starts."""
    if GLASS_SLOW and float(rate) == GLASS_SLOW["rate"] and float(phi) <= GLASS_SLOW["from_phi"]:
        rate = min(GLASS["rates"])
    return f"results/glass/{system}/g{float(rate):g}/phi{float(phi):g}/seed{seed}.nc"


def glass_continues_option(wildcards):
    """The `hardpack glass-eos --continues` option of a system with the slow branch."""
    if GLASS_SLOW and GLASS_SLOW["rate"] in GLASS_SYSTEMS[wildcards.system]["rates"]:
        return f"--continues {GLASS_SLOW['rate']:g} {min(GLASS['rates']):g}"
    return ""


def glass_previous(wildcards):
    """The packing a compression stage starts from: the previous stage's, the RSA start, or (the
    slow branch's first stage) the slowest of glass.rates at from_phi."""
    stages = GLASS_SYSTEMS[wildcards.system]["stages"]
    k = [f"{p:g}" for p in stages].index(wildcards.phi)
    if k == 0:
        return f"results/glass/{wildcards.system}/init/seed{wildcards.seed}.nc"
    return glass_snapshot(wildcards.system, wildcards.rate, stages[k - 1], wildcards.seed)


def glass_timeseries(system):
    spec = GLASS_SYSTEMS[system]
    files = [f"results/glass/{system}/g{rate:g}/phi{phi:g}/ts_seed{seed}.nc"
             for rate in spec["rates"] for phi in glass_stages(system, rate) for seed in GLASS["seeds"]]
    if system == "mono":
        files += [f"results/glass/mono/decompression/ts_seed{seed}.nc" for seed in GLASS["seeds"]]
    return files


# Micro-segregated packings (Donev 2006, sec. 13.5): ensemble name -> Matérn (R, nu). "random" is
# the uncorrelated labelling (the MRJ reference): R = 0.01 makes the Matérn correlation of
# neighbouring sites exp(-100) at nu = 1/2, i.e. independent labels.
MICROSEG_RANDOM = (0.01, 0.5)


def _microseg_ensembles():
    if not MICROSEG:
        return {}
    out = {"random": MICROSEG_RANDOM}
    out.update({f"R{R:g}_nu{nu:g}": (R, nu) for R in MICROSEG["R"] for nu in MICROSEG["nu"]})
    return out


MICROSEG_ENSEMBLES = _microseg_ensembles()


def microseg_packings():
    """Every jammed micro-segregated packing: realisations 0 .. packings - 1 of each ensemble."""
    return [f"results/microseg/{name}/r{k}.nc" for name in MICROSEG_ENSEMBLES
            for k in range(MICROSEG["packings"])] if MICROSEG else []


def microseg_minutes(w):
    """Expected minutes of one micro-segregated packing: ~45 / gamma collisions per particle for the
    growth and ~25 / Gamma for the compression to p = 1e12 (measured at N = 1024, gamma = Gamma =
    1e-3: 4.5e4 and 2.5e4), at ~4e5 collisions per second (deforming-cell kernel, one core)."""
    n = MICROSEG["shape"][0] * MICROSEG["shape"][1]
    per_particle = 45.0 / MICROSEG["growth_rate"] + 25.0 / MICROSEG["compress_rate"]
    return 0.3 + n * per_particle / 4e5 / 60


def glass_relaxed_files(prefix):
    """The relaxed-glass packings of every fast rate and seed: ``fast_`` after the fast compression,
    ``""`` after the recompression (in the same order)."""
    relaxed = GLASS.get("relaxed") or {}
    return [f"results/glass/binary/relaxed/g{rate:g}/{prefix}seed{seed}.nc"
            for rate in relaxed.get("rates", []) for seed in GLASS["seeds"]]


def glass_bcmd_files(system):
    """BCMD of the snapshots of the slowest compression (:func:`glass_snapshot`)."""
    rate = min(GLASS_SYSTEMS[system]["rates"])
    return [glass_snapshot(system, rate, phi, seed).replace(f"glass/{system}/", f"glass/{system}/bcmd/", 1)
            for phi in sorted(GLASS["snapshots"]) for seed in GLASS.get("bcmd_seeds", GLASS["seeds"])]


def glass_soc_files(kind):
    """The SOC solids of the mixture (Donev 2006, Fig. 13.9), one per snapshot of the slowest
    compression and glass.soc seed: ``ts_`` their compressions, ``relaxed_`` their relaxations
    without cells."""
    spec = GLASS.get("soc") if GLASS else None
    if not spec:
        return []
    return [f"results/glass/binary/soc/phi{phi:g}/{kind}seed{seed}.nc"
            for phi in sorted(GLASS["snapshots"]) for seed in spec["seeds"]]


def glass_soc_snapshot(wildcards):
    """The snapshot of the mixture's slowest compression a SOC solid starts from."""
    return glass_snapshot("binary", min(GLASS_SYSTEMS["binary"]["rates"]), wildcards.phi, wildcards.seed)


def glass_relaxation_files():
    """Pressure relaxation of the mixture at fixed glass.relaxation.phi, one run per compression
    rate and seed, started from that rate's snapshot (Donev 2006, Fig. 13.7)."""
    spec = GLASS.get("relaxation") if GLASS else None
    if not spec:
        return []
    return [f"results/glass/binary/relaxation/g{rate:g}/seed{seed}.nc"
            for rate in GLASS_SYSTEMS["binary"]["rates"] for seed in spec["seeds"]]


def glass_separated_files():
    """Time series of the phase-separated crystal's decompressions (glass.separated), per rate and seed."""
    spec = GLASS.get("separated") if GLASS else None
    if not spec:
        return []
    return [f"results/glass/separated/g{rate:g}/ts_seed{seed}.nc" for rate in spec["rates"] for seed in spec["seeds"]]


def glass_crystal_bcmd_files():
    """BCMD of the defect-free monodisperse crystal (glass.mono.crystal_bcmd), per density and seed."""
    spec = GLASS["mono"].get("crystal_bcmd")
    if not spec:
        return []
    return [f"results/glass/mono/crystal_bcmd/phi{phi}/seed{seed}.nc" for phi in spec["phis"] for seed in spec["seeds"]]


def glass_crystal_cells():
    """(nx, ny) of the triangular crystal of N = 2 nx ny disks, the box closest to square (nx ~ 2 ny)."""
    half = GLASS["N"] // 2
    ny = min((k for k in range(1, half + 1) if half % k == 0), key=lambda k: abs(half // k - 2 * k))
    return half // ny, ny


GLASS_PHI = r"0\.[0-9]+"


def glass_minutes_compress(n, rate, phi0, phi1):
    """Expected minutes of one stage from phi0 to phi1: collisions per particle ~ 0.55 (H(phi1) -
    H(phi0)) / Gamma with H Henderson's EOS integral (a proxy of the binary-disk one; measured
    N = 256, Gamma = 1e-3, 0.05 -> 0.80: 3.2e3 per particle), at 1e6 collisions per second in 2D."""
    def henderson_excess(p):
        return 9 / 8 * p / (1 - p) - 7 / 8 * math.log(1 - p)
    collisions = 0.55 * abs(henderson_excess(phi1) - henderson_excess(phi0)) / abs(rate) * n
    return 0.3 + collisions / 1e6 / 60


def glass_stage_minutes(w):
    spec = GLASS_SYSTEMS[w.system]
    stages = spec["stages"]
    k = [f"{p:g}" for p in stages].index(w.phi)
    phi0 = GLASS["init_phi"] if k == 0 else stages[k - 1]
    return glass_minutes_compress(GLASS["N"], float(w.rate), phi0, stages[k])


def glass_bcmd_thermostat(w):
    """The `hardpack bcmd` thermostat option of the glass rule (glass.bcmd.reset_ratio)."""
    ratio = GLASS["bcmd"].get("reset_ratio")
    return f"--reset-ratio {ratio:g}" if ratio else ""


def glass_bcmd_minutes(w):
    """BCMD from dmu_max to the disjoint point dmu_min ~ delta (the radii are shrunk by delta).
    The cells shrink at d(dmu)/dt = -gamma0 dmu / dmu_max (theta = 1), so the run lasts
    ~dmu_max / gamma0 ln(dmu_max / dmu_min), and a disk in a cell of size dmu collides at a rate
    ~sqrt(kT) / dmu. With the re-draw thermostat kT stays put: events per disk
    ~c dmu_max / (gamma0 dmu_min); without it kT grows as 1 / dmu^2: ~c' dmu_max / (gamma0 dmu_min^2).
    Measured (binary glasses at phi = 0.80, gamma0 = 1e-3, delta = 1e-3): with reset_ratio 2,
    3.6e5 events per disk at N = 256 (c = 0.37); without, 1.4e7 at N = 256 and ~1.2e7 at N = 4096
    (c' = 0.015); 5e6 events per second (7.7e6 measured at N = 4096)."""
    b = GLASS["bcmd"]
    if b.get("reset_ratio"):
        per_disk = 0.37 * b["dmu_max"] / (b["gamma0"] * b["delta"])
    else:
        per_disk = 0.015 * b["dmu_max"] / (b["gamma0"] * b["delta"] ** 2)
    return 0.3 + GLASS["N"] * per_disk / 5e6 / 60

# ---------------------------------------------------------------------------------------------
# Summaries: results/{key}_summary.nc. COMBINED are written by `hardpack combine` (the per-seed
# files as one Dataset indexed by their attributes), EOS_SUMMARIES by `hardpack poly-summary`.

JAMMING_VARIABLES = ("z_mean", "rattler_fraction", "isostaticity_gap", "local", "collective", "strict",
                     "fallback_lp_default_tolerances", "fallback_lp_working_set_to_highs",
                     "fallback_uniform_forces_lp_failed", "ellipse_slope")


#: per-packing numbers of the ellipsoid contact analysis (workflow/scripts/ellipsoid_contacts.py)
ELLIPSOID_VARIABLES = ("z_mean", "z_all", "rattler_fraction", "nematic_S", "pressure", "phi_J_est",
                       "collisions", "wall_time")


#: per-packing numbers of the ellipsoid jamming verdicts (hardpack verify --delta gaps --refine)
ELLIPSOID_VERDICT_VARIABLES = ("verdict", "jammed", "order_code", "hypostatic", "z_mean", "rattler_fraction",
                               "isostaticity_gap", "n_floppy", "n_stresses", "approximate_stress",
                               "stress_residual", "stress_gap", "delta", "delta_ambiguous", "lambda_min",
                               "stiffness_scale", "n_backbone", "jamming_distance", "refined", "ascended",
                               "ascent_confirmed")


def _combined(inputs, index, variables=(), attrs=None):
    options = [f"--index {' '.join(index)}", *(f"--variable {v}" for v in variables), attr_options(attrs or {})]
    return {"inputs": inputs, "options": " ".join(o for o in options if o)}


def _combined_summaries():
    table = {}
    for name, spec in SYSTEMS["ls"].items():
        attrs = {"ensemble": name, "distribution": json.dumps(spec["distribution"])}
        table[f"ls/{name}/init"] = _combined(seed_files("ls", name, "init"), ["seed"], ["init_phi"],
                                             {"ensemble": name})
        table[f"ls/{name}/jammed"] = _combined(seed_files("ls", name, "jammed"), ["seed"],
                                               ["Z", "phi_J_est", "collisions", "wall_time", "growth_rate"], attrs)
        table[f"ls/{name}/verdict"] = _combined(seed_files("ls", name, "verdict"), ["seed"], JAMMING_VARIABLES, attrs)
    for name, spec in SYSTEMS["strict_ls"].items():
        attrs = {"ensemble": spec["attrs"]["ensemble"], "d": spec["d"]}
        table[f"strict_ls/{name}/jammed"] = _combined(seed_files("strict_ls", name, "jammed"), ["seed"],
                                                      ["Z", "phi_J_est", "collisions", "wall_time"], attrs)
        table[f"strict_ls/{name}/verdict"] = _combined(seed_files("strict_ls", name, "verdict"), ["seed"],
                                                       JAMMING_VARIABLES, attrs)
    for name, spec in SYSTEMS["slp_mrj"].items():
        attrs = {"ensemble": name, "distribution": json.dumps(spec["distribution"])}
        table[f"slp_mrj/{name}/slp"] = _combined(seed_files("slp_mrj", name, "slp"), ["seed"],
                                                 ["n_steps", "wall_seconds", "cpu_seconds"], attrs)
        table[f"slp_mrj/{name}/verdict"] = _combined(seed_files("slp_mrj", name, "verdict"), ["seed"],
                                                     JAMMING_VARIABLES, attrs)
    if LS_DENSEST:
        table["ls_densest/jammed"] = _combined(
            [path for name in SYSTEMS["ls_densest"] for path in seed_files("ls_densest", name, "jammed")],
            ["d", "seed"], ["Z", "collisions", "wall_time", "growth_rate"])
    if SLP_DENSEST:
        table["slp_densest/slp"] = _combined(
            [path for name in SYSTEMS["slp_densest"] for path in seed_files("slp_densest", name, "slp")],
            ["d", "seed"], ["n_steps", "n_rejected", "wall_seconds", "cpu_seconds", "converged"])
    if FREEENERGY:
        for state in ("melting", "jamming"):
            table[f"bcmd_fcc/{state}"] = _combined(bcmd_files(state), ["n_particles", "seed"],
                                                   ["delta_f", "excess", "f", "n_events", "seconds"], {"state": state})
        table["bcmd_fcc/density"] = _combined(bcmd_files("density"), ["phi", "seed"],
                                              ["delta_f", "excess", "n_particles", "n_events", "seconds"],
                                              {"state": "density"})
        table["bcmd_fcc/eos"] = _combined(bcmd_files("eos"), ["phi"], ["Z", "Z_err", "N", "wall_time"], {"state": "eos"})
        ensemble = FREEENERGY["simplex"]["ensemble"]
        table[f"bcmd_simplex/{ensemble}/simplex"] = _combined(
            simplex_files(ensemble), ["seed", "frozen"],
            ["exact", "bcmd", "rel_diff", "isostatic", "isostaticity_gap", "n_backbone", "dim", "n_events",
             "seconds_bcmd", "next_gap"])
        if FREEENERGY.get("ellipse"):
            table["bcmd_ellipse/ellipse"] = _combined(
                ellipse_bcmd_files(), ["seed"],
                ["f_j_minus_fcj", "exact", "bcmd", "exact_in_cells", "inside_fraction", "inside_fraction_err",
                 "n_eff", "n_particles", "n_fixed_translation", "n_events", "seconds", "next_gap"])
    if GLASS and glass_crystal_bcmd_files():
        table["glass/mono/crystal_bcmd"] = _combined(glass_crystal_bcmd_files(), ["phi", "seed"],
                                                     ["excess", "n_particles", "n_events", "seconds"])
    for dim in (2, 3):
        files = ellipsoid_files(dim, "contacts")
        if files:
            table[f"ellipsoids/contacts{dim}d"] = _combined(files, ["beta", "alpha", "seed"], ELLIPSOID_VARIABLES)
            table[f"ellipsoids/verdicts{dim}d"] = _combined(ellipsoid_files(dim, "verdict"), ["beta", "alpha", "seed"],
                                                            ELLIPSOID_VERDICT_VARIABLES)
    near = ellipsoid_files(3, "verdict", near_sphere=True)
    if near:
        table["ellipsoids/verdicts_near_sphere"] = _combined(near, ["beta", "alpha", "seed"], ELLIPSOID_VERDICT_VARIABLES)
    return table


def _eos_summaries():
    table = {}
    for protocol, runs in POLY_PROTOCOLS.items():
        for family in runs.get("widths", {}):
            table[f"poly_{protocol}/{family}"] = {"inputs": poly_jam_files(protocol, family),
                                                  "kind": POLY_SUMMARY_KIND[protocol]}
    if POLY_FLUID.get("widths"):
        table["poly_fluid/fluid"] = {"kind": "fluid", "inputs": [
            f"results/poly_fluid/{family}_w{poly_width(w)}/fluid.nc"
            for family, widths in POLY_FLUID["widths"].items() for w in widths]}
    return table


COMBINED = _combined_summaries()
EOS_SUMMARIES = _eos_summaries()


def summary(key):
    return f"results/{key}_summary.nc"


def one_of(keys):
    """A wildcard constraint matching exactly ``keys`` (never an empty match)."""
    return "|".join(re.escape(k) for k in keys) or "(?!)"


# ---------------------------------------------------------------------------------------------
# Final outputs: the figures the config enables, the summaries the validation report reads (by
# row builder, hardpack.validation.cli.ROW_BUILDERS), and the validation gate.

def monodisperse_ensembles():
    return [name for name, ens in ENSEMBLES.items() if ens["distribution"]["kind"] == "monodisperse"]


def structure_files():
    return [path for name in SYSTEMS["ls"] for path in seed_files("ls", name, "structure")]


def rate_timeseries():
    return [path for name in SYSTEMS["ls_rates"] for path in seed_files("ls_rates", name, "timeseries")]


def figures():
    """The figures the config enables (results/figures/*.pdf; each has a .png beside it)."""
    names = ["size_distributions"]
    names += ["jamming_vs_d"] if monodisperse_ensembles() else []
    names += ["ls_rates_phij", "ls_rates_eos"] if RATES else []
    names += [f"structure_{kind}" for kind in ("g2", "zl", "sk", "channels")]
    names += ["slp_densest"] if SLP_DENSEST else []
    names += ["slp_vs_ls"] if SLP_MRJ else []
    names += ["slp_order_map"] if SLP_ORDER or SLP_DILUTED else []
    names += ["bcmd_fcc", "bcmd_fcc_density"] if FREEENERGY else []
    names += ["phij_vs_omega"] if POLY_PROTOCOLS["phij"].get("widths") else []
    names += ["crystallisation_vs_omega"] if POLY_PROTOCOLS["crystallisation"].get("widths", {}).get("uniform_size") else []
    names += ["eos_vs_bmcsl"] if POLY_FLUID.get("widths") else []
    names += ["ellipsoid_jamming"] if any(s["d"] == 3 for s in SYSTEMS["ellipsoids"].values()) else []
    names += ["ellipse_jamming"] if any(s["d"] == 2 for s in SYSTEMS["ellipsoids"].values()) else []
    names += ["ellipsoid_snapshot"] if ELLIPSOIDS and "mm" in ELLIPSOIDS else []
    names += ["laminate_crystals"] if ELLIPSOID_CRYSTALS else []
    names += ["glass_eos", "glass_entropy", "glass_cell_pressure", "glass_separated"] if GLASS else []
    names += ["glass_crystal"] if GLASS and glass_crystal_bcmd_files() else []
    names += ["glass_relaxation"] if GLASS and glass_relaxation_files() else []
    names += ["glass_soc"] if GLASS and glass_soc_files("") else []
    names += ["glass_jamming"] if GLASS and GLASS.get("relaxed") else []
    names += ["microsegregated", "microsegregated_maps"] if MICROSEG else []
    names += ["container_profile", "container_extrapolation", "container_windows"] if CONTAINERS else []
    names += ["ellipsoid_container_profile"] if ELLIPSOID_CONTAINERS else []
    names += ["strict_ls_disks"] if "d2" in SYSTEMS["strict_ls"] else []
    return [f"results/figures/{name}.pdf" for name in names]


def crystal_search_outputs():
    """The crystal-search datasets, one per aspect ratio of the config (none without a search)."""
    return [f"results/ellipsoid_crystals/search/alpha{alpha}.nc" for alpha in (CRYSTAL_SEARCH or {}).get("alphas", [])]


def validation_inputs():
    """Row-builder name -> the summaries it reads, for every study the config enables."""
    inputs = {
        "ls": [summary(f"ls/{name}/jammed") for name in SYSTEMS["ls"]],
        "jamming": [summary(f"ls/{name}/verdict") for name in SYSTEMS["ls"]],
        "structure": structure_files(),
    }
    if SLP_DENSEST:
        inputs["slp_densest"] = [summary("slp_densest/slp")]
    if LS_DENSEST:
        inputs["ls_densest"] = [summary("ls_densest/jammed")]
    if SLP_MRJ:
        inputs["slp_mrj"] = [summary(f"slp_mrj/{name}/slp") for name in SYSTEMS["slp_mrj"]]
        inputs["slp_jamming"] = [summary(f"slp_mrj/{name}/verdict") for name in SYSTEMS["slp_mrj"]]
    if SLP_ORDER:
        inputs["slp_order_map"] = [summary("slp_order_map/order_map")]
    if SLP_DILUTED:
        inputs["slp_diluted"] = [summary(f"slp_diluted/{SLP_DILUTED['ensemble']}/diluted")]
    if FREEENERGY:
        inputs["bcmd"] = [summary("bcmd_fcc/melting"), summary("bcmd_fcc/jamming")]
        inputs["bcmd_density"] = [summary("bcmd_fcc/density"), summary("bcmd_fcc/eos")]
        inputs["bcmd_simplex"] = [summary(f"bcmd_simplex/{FREEENERGY['simplex']['ensemble']}/simplex")]
        inputs["bcmd_ladder"] = ["results/bcmd_ladder/ladder.nc"]
        if FREEENERGY.get("ellipse"):
            inputs["bcmd_ellipse"] = [summary("bcmd_ellipse/ellipse")]
            inputs["bcmd_ellipse_ladder"] = ["results/bcmd_ellipse/ladder.nc"]
    if GLASS:
        inputs["glass_eos"] = [summary("glass/binary/eos"), summary("glass/mono/eos")]
        inputs["glass_entropy"] = [summary("glass/binary/entropy"), summary("glass/mono/entropy")]
        inputs["glass_freezing"] = [summary("glass/freezing")]
        if glass_crystal_bcmd_files():
            inputs["glass_crystal"] = [summary("glass/mono/crystal_bcmd"), summary("glass/mono/eos")]
        if GLASS.get("relaxed"):
            inputs["glass_relaxed"] = [summary("glass/binary/relaxed")]
        if GLASS.get("soc"):
            inputs["glass_soc"] = [summary("glass/binary/soc")]
    if MICROSEG:
        inputs["glass_microsegregated"] = [summary("microseg/phij_sc")]
    poly = [summary(key) for key in EOS_SUMMARIES]
    if poly:
        inputs["polydisperse"] = poly
    ellipsoids = [summary(key) for key in COMBINED if key.startswith("ellipsoids/contacts")]
    if ellipsoids:
        inputs["ellipsoids"] = ellipsoids
        inputs["ellipsoid_jamming"] = [summary(key) for key in COMBINED if key.startswith("ellipsoids/verdicts")]
    if ELLIPSOID_CRYSTALS:
        inputs["ellipsoid_crystals"] = ["results/ellipsoid_crystals/laminate_family.nc"]
        if CRYSTAL_SEARCH:
            inputs["crystal_search"] = crystal_search_outputs()
    if CONTAINERS:
        inputs["containers"] = ["results/containers/profile_summary.nc", "results/containers/windows_summary.nc"]
    if ELLIPSOID_CONTAINERS:
        inputs.setdefault("containers", []).extend(
            f"results/ellipsoid_containers/{shape}/summary.nc" for shape in ELLIPSOID_CONTAINERS["shapes"])
    if STRICT_LS:
        inputs["strict_ls"] = [summary(f"strict_ls/{name}/verdict") for name in SYSTEMS["strict_ls"]]
    return inputs


def validation_arguments():
    """The `hardpack validate` inputs NAME=PATH."""
    return " ".join(f"{name}={path}" for name, paths in validation_inputs().items() for path in paths)


def final_outputs():
    """What `all` builds: every LS ensemble's summaries, the figures, the validation inputs and the gate."""
    outputs = [summary(f"ls/{name}/{step}") for name in SYSTEMS["ls"] for step in ("init", "jammed", "verdict")]
    outputs += figures()
    outputs += [f"results/ellipsoids/verdict_fractions{key.removeprefix('ellipsoids/verdicts')}.nc"
                for key in COMBINED if key.startswith("ellipsoids/verdicts")]
    outputs += [path for paths in validation_inputs().values() for path in paths]
    outputs.append("results/validation/gate.txt")
    return list(dict.fromkeys(outputs))


# ---------------------------------------------------------------------------------------------
# Job resources (threads, mem_mb, runtime in minutes) of every rule, from one cost model: the
# expected wall minutes of a job on one core of the shared 2-core development machine, from the
# job's system (N, d, growth rate, rounds, collisions, ...), calibrated on the full study's job
# records (docs/cluster.md has the records and the fits). The limit is RUNTIME_SAFETY times the
# expectation plus RUNTIME_SLACK (start-up, a slower node), times the attempt: a job killed at its
# time limit is retried with a longer one and resumes from its checkpoint.

RUNTIME_SAFETY = 3
RUNTIME_SLACK = 5         # minutes
MEM_FLOOR_MB = 500        # a hardpack process (numpy, numba, xarray): max_rss 174-312 MB in the smoke study
MD_SECONDS_PER_UNIT = 3e-5  # LS compression: seconds per particle per unit of 1 / Gamma, in 3D
#: cost per collision against 3D (NVE rates, benchmarks/bench_md.py: 1.43e6, 8.0e5, 3.1e5, 1.7e5, 1.3e5 coll/s)
MD_DIMENSION_COST = {2: 0.6, 3: 1.0, 4: 2.6, 5: 4.7, 6: 6.2}
SLP_MINUTES_PER_N2 = 1.6e-5  # SLP to convergence, 3D: 1.6 min at N = 500, 6-24 min at N = 1000
#: SLP cost against 3D at the same N (2D N = 500: 12 s; 4D N = 250: 1.5 min; 5D N = 243: 6 min; 6D N = 250: 25 min)
SLP_DIMENSION_COST = {2: 0.05, 3: 1.0, 4: 1.5, 5: 6.5, 6: 25.0}
#: cost of an LS compression of ellipsoids against spheres at the same N, d and growth rate
#: (N = 1000, Gamma = 0.01: spheres 1.1e6 collisions/s, spheroids 1:1:1.5 9.5e3 /s)
ELLIPSOID_MD_COST = 100.0
#: rules that never take long: they run as one cluster job per group (--group-components in the
#: slurm profile), with these expected minutes
TINY_MINUTES = 0.3


def md_minutes(n, d, gamma):
    """Expected minutes of an LS compression of n particles whose slowest growth rate is gamma:
    the collisions to jamming grow as n / gamma (3D N = 1e4 at 1e-4: 46-58 min; N = 1000 at 3e-4:
    3 min)."""
    return 0.5 + MD_SECONDS_PER_UNIT * n / gamma * MD_DIMENSION_COST[d] / 60


def slp_minutes(n, d):
    """Expected minutes of an SLP run to convergence (Torquato & Jiao 2010 settings)."""
    return 0.3 + SLP_MINUTES_PER_N2 * n**2 * SLP_DIMENSION_COST[d]


def lp_minutes(n):
    """Expected minutes of the sequential jamming test and contact forces (3D N = 1000: under a
    second; N = 1e4: 4.5 min with two workers plus 0.5 min of forces)."""
    return 0.3 + 5.0 * (n / 1e4) ** 2


def ellipsoid_verify_minutes(n):
    """Expected minutes of the first- and second-order tests of n ellipsoids (benchmarks/
    bench_ellipsoid_jamming.py, CPU: N = 1000 spheroids decided at first order 9 s, N = 1080 at
    second order 42 s; N = 100: ~20 s)."""
    return 0.3 + 1.0 * (n / 1000) ** 1.5


def _slowest_rate(spec):
    rates = [float(r) for r in re.findall(r"--(?:final-)?growth-rate ([0-9.e+-]+)", spec["compress"])]
    return min(rates)


#: expected minutes of one job of each rule (rules not listed are TINY_MINUTES)
EXPECTED_MINUTES = {
    "compress": lambda w: md_minutes(system(w)["N"], system(w)["d"], _slowest_rate(system(w)))
    * (ELLIPSOID_MD_COST if "semiaxes" in system(w) else 1.0),
    "poly_jam": lambda w: md_minutes(poly_protocol(w)["N"], 3, poly_protocol(w)["final_growth_rate"]),
    "slp": lambda w: slp_minutes(system(w)["N"], system(w)["d"]),
    "slp_dilute": lambda w: system(w)["rounds"] * slp_minutes(system(w)["N"], system(w)["d"]),
    "verify": lambda w: lp_minutes(system(w)["N"]),
    "ellipsoid_verify": lambda w: ellipsoid_verify_minutes(SYSTEMS["ellipsoids"][w.name]["N"]),
    "structure": lambda w: 0.3 + system(w)["N"] / 2e4,
    "bcmd_fcc": lambda w: 0.3 + 4 * int(w.reps) ** 3 / 500,
    "fcc_eos": lambda w: 0.3 + FREEENERGY["density"]["eos_collisions"] / 6e7,
    "bcmd_simplex": lambda w: 0.3 + 3.0 * SYSTEMS["ls"][w.ensemble]["N"] / 1000,
    # 100 ellipses: LS to Z = 1e8 ~2 min; BCMD at gamma0 = 1e-3 ~7 min (2.2e7 events)
    "ellipse_lattice_jam": lambda w: 3.0,
    "bcmd_ellipse": lambda w: 0.5 if FREEENERGY["ellipse"].get("exact_only") else 0.5 + 7.0 * 1e-3 / FREEENERGY["ellipse"]["gamma0"],
    "poly_fluid": lambda w: 0.3 + 3 * len(POLY_FLUID["phi"]) * (POLY_FLUID["collisions"] + 50 * POLY_FLUID["N"]) / 6e6,
    "glass_compress": glass_stage_minutes,
    "glass_decompress": lambda w: glass_minutes_compress(GLASS["N"], GLASS["mono"]["rate"],
                                                         GLASS["mono"]["decompress_to"], GLASS["mono"]["crystal_phi"]),
    "glass_bcmd": glass_bcmd_minutes,
    "glass_separated_decompress": lambda w: glass_minutes_compress(
        sum(GLASS["separated"]["columns"][k] * GLASS["separated"]["rows"][k] for k in (0, 1)), float(w.rate),
        GLASS["separated"]["phi_end"], GLASS["separated"]["phi"]),
    # measured 2.7e6 collisions/s for the mixture at phi = 0.80 (N = 4096, 4.1e8 collisions in 150 CPU-s)
    "glass_relaxation": lambda w: 0.3 + GLASS["N"] * GLASS["relaxation"]["collisions_per_particle"] / 2.5e6 / 60,
    # the defect-free crystal (measured, N = 4096, gamma0 = 1e-3: 3.1e4 events per disk at phi = 0.75
    # in 44 s, 97 s at 0.80; ~3e6 events/s): <= 1e5 dmu_max / (1e3 gamma0) events per disk
    "glass_crystal_bcmd": lambda w: 0.3 + GLASS["N"] * 100 * GLASS["bcmd"]["dmu_max"] / GLASS["bcmd"]["gamma0"] / 3e6 / 60,
    # N = 1024, Gamma = 0.1, 1e4 collisions per particle, recompression at 1e-4 to Z = 1e4: ~20 CPU-s
    "glass_relaxed": lambda w: 0.3 + 0.5 * GLASS["N"] / 1024 * (1 + GLASS["relaxed"]["relax_collisions"] / 1e4),
    # SOC solids to Z = 1e3: ~5 / rate events per disk (N = 256, rate 1e-3, phi0 = 0.70-0.825: 2.9e3-4.7e3;
    # N = 4096, rate 1e-5, phi0 = 0.70: 4.5e5, 1.85e9 events in 2000 CPU-s, both cores busy)
    "glass_soc": lambda w: 0.3 + GLASS["N"] * 5.0 / GLASS["soc"]["rate"] / 9e5 / 60,
    "glass_soc_relaxation": lambda w: 0.3 + GLASS["N"] * GLASS["soc"]["relax_collisions_per_particle"] / 2.5e6 / 60,
    "microseg_packing": microseg_minutes,
    # per run at alpha = sqrt(3), CPU s: n = 1 about 2, n = 2 about 7, n = 4 8-10; oblate slower
    "crystal_search": lambda w: 1.0 + len(CRYSTAL_SEARCH["seeds"]) * sum(0.05 * n for n in CRYSTAL_SEARCH["n"])
    * (3.0 if float(w.alpha) < 1 else 1.0),
}


def expected_minutes(rule, wildcards):
    """Expected wall minutes of one job of ``rule`` on one core (the cost model above)."""
    cost = EXPECTED_MINUTES.get(rule)
    return cost(wildcards) if cost else TINY_MINUTES


def job_runtime(rule):
    """`resources: runtime=` of a rule: minutes, RUNTIME_SAFETY x expected + RUNTIME_SLACK, x attempt."""
    return lambda wildcards, attempt: attempt * math.ceil(RUNTIME_SAFETY * expected_minutes(rule, wildcards)
                                                          + RUNTIME_SLACK)


#: the number of particles a job holds in memory (jobs not listed: none to speak of)
PARTICLES = {
    **dict.fromkeys(("init", "compress", "slp", "slp_dilute", "verify", "structure"), lambda w: system(w)["N"]),
    "ellipsoid_verify": lambda w: SYSTEMS["ellipsoids"][w.name]["N"],
    "poly_jam": lambda w: poly_protocol(w)["N"],
    "bcmd_fcc": lambda w: 4 * int(w.reps) ** 3,
    "fcc_eos": lambda w: 4 * int(w.reps) ** 3,
    "bcmd_simplex": lambda w: SYSTEMS["ls"][w.ensemble]["N"],
    "poly_fluid": lambda w: POLY_FLUID["N"],
    **dict.fromkeys(("glass_init", "glass_crystal", "glass_compress", "glass_decompress", "glass_bcmd", "glass_crystal_bcmd",
                     "glass_relaxation", "glass_soc", "glass_soc_relaxation",
                     "glass_relaxed"), lambda w: GLASS["N"]),
    **dict.fromkeys(("glass_separated_crystal", "glass_separated_decompress"),
                    lambda w: sum(c * r for c, r in zip(GLASS["separated"]["columns"], GLASS["separated"]["rows"]))),
    **dict.fromkeys(("container_init", "container_profile"), lambda w: SYSTEMS["containers"][w.name]["N"]),
    **dict.fromkeys(("ellipsoid_container_init", "ellipsoid_container_profile"),
                    lambda w: SYSTEMS["ellipsoid_containers"][w.name]["N"]),
    "microseg_packing": lambda w: MICROSEG["shape"][0] * MICROSEG["shape"][1],
}


#: MB per particle of each rule's process (LS engine 3D N = 1e4: 257 MB in all; an LP jamming
#: worker at N = 1e4: ~1 GB; SLP keeps its LPs' constraint matrices)
MEM_MB_PER_PARTICLE = {"verify": 0.12, "slp": 1.5, "slp_dilute": 1.5, "bcmd_simplex": 0.5}


def job_mem_mb(rule):
    """`resources: mem_mb=` of a rule: MEM_FLOOR_MB plus MB per particle, per process (a verify
    job's loading-sequence workers are one process per thread besides the main one)."""
    def mem_mb(wildcards, threads):
        processes = threads + 1 if rule == "verify" and threads > 1 else 1
        per_particle = MEM_MB_PER_PARTICLE.get(rule, 0.1)
        particles = PARTICLES[rule](wildcards) if rule in PARTICLES else 0
        return math.ceil(MEM_FLOOR_MB + processes * per_particle * particles)
    return mem_mb


def verify_threads(wildcards):
    """Loading sequences run side by side (hardpack verify --workers) for large packings, whose
    strict sequences take a minute or more each (N = 1e4 in 3D: 1-1.5 min, 2-3 LPs)."""
    return 2 if system(wildcards)["N"] >= 5000 else 1
