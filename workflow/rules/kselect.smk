# K chosen from the data: ours trained with K from held-out training frames or BIC (`auto`),
# evaluated and scored by the generic `evaluate` and `recovery` rules, and compared with the
# fixed K in tab_kselect (built by the generic `table` rule).


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
    threads: 2
    resources:
        mem_mb=4000,
        # minutes; about 1 s per iteration per candidate, generous for a cluster
        runtime=10
        + len(CFG["models"]["kselect"]["candidates"])
        * CFG["models"]["kselect"]["iterations"]
        // 60,
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
        job=lambda wc: _job_spec(CFG, "ours", _models.BASE_CONFIG, seed=int(wc.seed)),
        conditions=CFG["models"]["kselect"]["conditions"],
    script:
        "../scripts/train_auto.py"
