# K chosen from the data: ours trained with K from held-out training frames or BIC (`auto`),
# evaluated and scored by the generic `evaluate` and `recovery` rules, and compared with the
# fixed K in tab_kselect (built by the generic `table` rule). The priors under
# models/kselect/priors (the chained prior) are chosen and trained by the same rules with a
# {model} wildcard (`kselect_prior`, `train_auto_prior`), with their own candidates and schedule.


rule kselect:
    input:
        observed=observed_input,
    output:
        selection=KSELECT,
    log:
        "logs/kselect/{tree}/seed{seed}.log",
    benchmark:
        "results/benchmarks/kselect/{tree}/seed{seed}.tsv"
    conda:
        "../envs/physgs.yaml"
    # one thread: a two-thread job on two cores starts only when both are free, which never
    # happens while one-thread jobs are ready, so every selection waited for the run's end
    threads: 1
    resources:
        mem_mb=4000,
        # minutes; about 1 s per iteration per candidate, generous for a cluster
        runtime=kselect_runtime(_kselect.BASE_MODEL),
    params:
        settings=kselect_params,
    script:
        "../scripts/kselect.py"


rule train_auto:
    input:
        observed=observed_input,
        selection=KSELECT,
    output:
        ckpt=CKPT.replace("{model}_{config}", "ours_auto"),
        loss=LOSS.replace("{model}_{config}", "ours_auto"),
    log:
        "logs/train/{tree}/seed{seed}/ours_auto.log",
    benchmark:
        "results/benchmarks/train/{tree}/seed{seed}/ours_auto.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=4000,
        runtime=10 + CFG["train"]["iterations"] // 60,
    params:
        job=lambda wc: _job_spec(CFG, "ours", _models.BASE_CONFIG, seed=int(wc.seed), tree=wc.tree),
        conditions=CFG["models"]["kselect"]["conditions"],
    script:
        "../scripts/train_auto.py"


use rule kselect as kselect_prior with:
    output:
        selection=PRIOR_KSELECT,
    log:
        "logs/kselect/{tree}/seed{seed}/{model}.log",
    benchmark:
        "results/benchmarks/kselect/{tree}/seed{seed}/{model}.tsv"
    wildcard_constraints:
        model="|".join(KSELECT_PRIORS) or "^$",  # none listed: the rule matches nothing
    resources:
        mem_mb=4000,
        runtime=lambda wc: kselect_runtime(wc.model),


use rule train_auto as train_auto_prior with:
    input:
        observed=observed_input,
        selection=PRIOR_KSELECT,
    output:
        ckpt=CKPT.replace("{config}", _models.AUTO_CONFIG),
        loss=LOSS.replace("{config}", _models.AUTO_CONFIG),
    log:
        "logs/train/{tree}/seed{seed}/{model}_auto.log",
    benchmark:
        "results/benchmarks/train/{tree}/seed{seed}/{model}_auto.tsv"
    wildcard_constraints:
        model="|".join(KSELECT_PRIORS) or "^$",
    params:
        job=lambda wc: _job_spec(
            CFG, wc.model, _models.BASE_CONFIG, seed=int(wc.seed), tree=wc.tree
        ),
        conditions=CFG["models"]["kselect"]["conditions"],
