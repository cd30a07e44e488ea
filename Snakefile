# physgs: does a dynamic 3DGS reconstruction of a wind-driven tree recover physics?
# Profiles: --config profile=quick|default|paper (default: config/trees.yaml's `profile`).
from snakemake.utils import min_version

import physgs.config
import physgs.experiments.recipe
import physgs.provenance
import physgs.scheduling

min_version("9.0")
# Snakemake's loop adds a re-evaluation timer chain per finished job, and a long run's loop then
# takes most of a core from the jobs: keep one pending timer (physgs.scheduling)
physgs.scheduling.install()
# Snakemake's own message for a YAML syntax error names no file, line or column: parse it first
physgs.config.check_yaml_syntax("config/trees.yaml")
# a results folder without Snakemake's metadata (copied, or older) is taken as up to date whatever
# settings made it: every plan checks each file it reads as made against the provenance record
# beside it (physgs.provenance), and names the file and the key that differs
physgs.provenance.install(workflow)


configfile: "config/trees.yaml"


# validates the raw config and every profile body against the packaged schema, resolves the
# profile, validates the result and runs the cross-key checks: a bad config stops here
# (what --config and --configfile set, at any depth, beats the profile: physgs.config)
CFG = physgs.config.load_workflow_config(
    config,
    command_line=dict(workflow.config_settings.config),
    configfiles=workflow.config_settings.configfiles,
)
TREES = CFG["trees"]
# a bfloat16 field on a CPU that would emulate bf16 (~48x slower) stops here, before any job
# (torch loads only when a field asks for bf16 and the CPU's flags do not report it)
physgs.experiments.recipe.check_precision_supported(CFG["models"], planning=True)


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/testbed.smk"
include: "workflow/rules/train.smk"
include: "workflow/rules/evaluate.smk"
include: "workflow/rules/recovery.smk"
include: "workflow/rules/parts.smk"
include: "workflow/rules/tracks.smk"
include: "workflow/rules/oma.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/speed_accuracy.smk"
include: "workflow/rules/kselect.smk"
include: "workflow/rules/search.smk"


# everything `all` makes besides the summary, which reads these runs' benchmark files: the
# paper's tables at every seed. The studies of the trade (the speed-accuracy sweep, the fit curve,
# the chained prior's K match) are a target of their own, `studies`, at the studies' seeds: three
# seeds of `all` already take over 3 h of the 2 cores (docs/performance.md, What a run costs)
RUN = [
    rules.testbed.input,
    rules.report.input,
    expand(TABLE, name="tab_kselect", ext=("tex", "csv")),
    rules.claims.output,
    rules.oma.input,  # the stabilisation diagrams (the records are in tab_recovery / tab_damping)
]


include: "workflow/rules/summary.smk"


rule all:
    input:
        RUN,
        rules.summary.output,


rule studies:
    input:
        rules.speed_accuracy.output,
        rules.fit_curve.output,
        expand(
            FIGURE,
            name=("fig_speed_accuracy", "fig_fit_curve", "fig_fit_vs_extrapolation"),
            ext=("pdf", "png"),
        ),
        expand(TABLE, name="tab_parts_k", ext=("tex", "csv"))
        if "ours_chain" in PARTS_MODELS
        else [],


# On SLURM, a request that no node of its partition can meet would wait PENDING for ever: every
# job's threads, memory and run time are checked against `sinfo` before the first submission.
onstart:
    if workflow.executor_plugin is not None and workflow.executor_plugin.name == "slurm":
        import physgs.cluster

        physgs.cluster.check_jobs(workflow.dag.needrun_jobs())
