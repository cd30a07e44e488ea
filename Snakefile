# physgs: does a dynamic 3DGS reconstruction of a wind-driven tree recover physics?
# Profiles: --config profile=quick|default|paper (default: config/trees.yaml's `profile`).
from snakemake.utils import min_version, validate

import physgs.config

min_version("9.0")


configfile: "config/trees.yaml"


validate(config, "workflow/schemas/config.schema.yaml")
CFG = physgs.config.resolve(config, config.get("profile"))
validate(CFG, "workflow/schemas/config.schema.yaml")
TREES = CFG["trees"]


include: "workflow/rules/common.smk"
include: "workflow/rules/testbed.smk"
include: "workflow/rules/train.smk"
include: "workflow/rules/evaluate.smk"
include: "workflow/rules/recovery.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/speed_accuracy.smk"
include: "workflow/rules/kselect.smk"


rule all:
    input:
        rules.testbed.input,
        rules.report.input,
        rules.speed_accuracy.output,
        rules.tab_kselect.output,
