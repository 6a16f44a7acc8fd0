# hardpack: the studies as one Snakemake DAG.
#   snakemake --cores all                                  full study (config/config.yaml)
#   snakemake --cores 2 --configfile config/smoke.yaml     tiny systems, same DAG (CI)
#   snakemake --cores 1 results/figures/<name>.pdf         one figure and only what it needs
# Rules are thin: they call the `hardpack` CLI or a short script under workflow/scripts/. The
# results layout, the config checks and the list of final outputs are in workflow/rules/common.smk.

# --configfile replaces the default study instead of being merged into it
if not config:
    configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/packings.smk"      # generic jobs of the packing studies: init, compress, slp, verify, structure, combine
include: "workflow/rules/ls.smk"            # LS figures: size distributions, phi_J vs d, growth rates, structure
include: "workflow/rules/slp.smk"           # SLP order map and diluted MRJ summaries, SLP figures
include: "workflow/rules/freeenergy.smk"    # BCMD free energies of FCC and of LS packings
include: "workflow/rules/polydisperse.smk"  # polydisperse vs bi- and tridisperse equivalents
include: "workflow/rules/ellipsoids.smk"     # hard ellipsoids and ellipses: contacts, figures after Figs. 5.1-5.3
include: "workflow/rules/containers.smk"    # spheres in spherical containers, window fluctuations (Donev 2006, Sec. 7.3)
include: "workflow/rules/strict.smk"        # strictly jammed LS packings in a deforming cell (Donev 2006, Sec. 4.7.2.3)
include: "workflow/rules/glass.smk"         # binary hard-disk glasses: EOS, fits, SOC free energies, s_c
include: "workflow/rules/microsegregated.smk"  # micro-segregated binary disk packings: phi_J vs s_c (Donev 2006, sec. 13.5)
include: "workflow/rules/validation.smk"    # validation report and gate


localrules:
    all,


rule all:
    input:
        final_outputs(),
