# Recovery (SPEC section 4): match ours' parts to bones by trajectory, against an untrained null.
# The null control is keyed by K: configurations sharing a K share one null.


rule recovery:
    input:
        ckpt=CKPT.replace("{model}", "ours"),
        observed=OBSERVED,
        truth=TRUTH,
        stats=STATS,
    output:
        record=RECOVERY,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/recovery/{tree}/ours_{config}.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    script:
        "../scripts/recovery.py"


rule null_control:
    input:
        observed=OBSERVED,
        truth=TRUTH,
        stats=STATS,
    output:
        record=NULL,
    params:
        null=null_params,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/recovery/{tree}/null_K{K}.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    script:
        "../scripts/null_control.py"
