# Training: one job per (tree, model, configuration). The only input is the observed dataset;
# the ground-truth physics file (truth.npz) is never an input of a training rule.
rule train:
    input:
        observed=train_input,
    output:
        ckpt="results/models/{tree}/{model}_{config}.pt",
        loss="results/models/{tree}/{model}_{config}.loss.csv",
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
        model="|".join(_models.MODEL_NAMES),
        config="|".join(_models.CONFIG_NAMES),
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/train/{tree}/{model}_{config}.log",
    benchmark:
        "results/benchmarks/train/{tree}/{model}_{config}.tsv"
    threads: 1  # two 1-thread jobs side by side beat one 2-thread job on 2 cores (benchmarks/training.py)
    resources:
        mem_mb=4000,
        # minutes; generous (about 1 s per iteration) so a cluster never kills a default job
        runtime=10 + CFG["train"]["iterations"] // 60,
    script:
        "../scripts/train.py"


rule train_all:
    input:
        expand("results/models/{tree}/{job}.pt", tree=TREES,
               job=[f"{m}_{c}" for m, c in TRAIN_JOBS]),
