# Recovery (the protocol, section 4): match an oscillator prior's parts to bones by trajectory (ours and the
# parts study's variants), against an untrained null.
# The null control is keyed by K and seed: configurations sharing a K share one null, and each
# training seed draws its own (paired with that seed's trained model in tab_null).


rule recovery:
    input:
        ckpt=recovery_ckpt,
        observed=observed_input,
        truth=truth_input,
        stats=stats_input,
    output:
        record=RECOVERY,
    log:
        "logs/recovery/{tree}/seed{seed}/{method}_{config}.log",
    wildcard_constraints:
        # a trained prior's record: the recovery methods whose entry names this rule
        # (registry.RECOVERY_METHODS) and the parts study's variants (tab_parts)
        method="|".join(
            m for m in (*_models.MODEL_NAMES, *_models.PRIOR_VARIANT_NAMES) if _models.is_prior(m)
        ),
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        damping=recovery_damping_params,
    script:
        "../scripts/recovery.py"


rule null_control:
    input:
        observed=observed_input,
        truth=truth_input,
        stats=stats_input,
    output:
        record=NULL,
    log:
        "logs/recovery/{tree}/seed{seed}/null_K{K}.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        null=null_params,
    script:
        "../scripts/null_control.py"
