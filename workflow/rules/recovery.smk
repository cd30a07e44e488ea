# Recovery (SPEC section 4): match ours' parts to bones by trajectory, against an untrained null.


rule recovery:
    input:
        ckpt="results/models/{tree}/ours_{config}.pt",
        observed="results/testbed/{tree}/observed.npz",
        truth="results/testbed/{tree}/truth.npz",
    output:
        record=_build.RECOVERY,
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
        config="|".join((*_models.CONFIG_NAMES, _models.AUTO_CONFIG)),
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
        observed="results/testbed/{tree}/observed.npz",
        truth="results/testbed/{tree}/truth.npz",
    output:
        record=_build.NULL,
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
        config="|".join((*_models.CONFIG_NAMES, _models.AUTO_CONFIG)),
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/recovery/{tree}/null_{config}.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    script:
        "../scripts/null_control.py"
