# Training: one job per (tree, model, configuration). The only input is the observed dataset;
# the ground-truth physics file (truth.npz) is never an input of a training rule. The job's
# params are its narrow settings (physgs.experiments.recipe.job_spec): editing another model's
# settings, the sweep or a table's format leaves it up to date.


rule train:
    input:
        observed=train_input,
    output:
        ckpt=CKPT,
        loss=LOSS,
    log:
        "logs/train/{tree}/seed{seed}/{model}_{config}.log",
    benchmark:
        "results/benchmarks/train/{tree}/seed{seed}/{model}_{config}.tsv"
    wildcard_constraints:
        # methods and the parts study's prior variants; the reference has its own rule
        model="|".join([*_models.MODEL_NAMES, *_models.PRIOR_VARIANT_NAMES]),
        config="|".join(CONFIGS),  # ours_auto has its own rule (kselect.smk)
    conda:
        "../envs/physgs.yaml"
    threads: 1  # two 1-thread jobs side by side beat one 2-thread job on 2 cores (benchmarks/training.py)
    resources:
        mem_mb=4000,
        runtime=train_runtime,
    params:
        job=train_params,
    script:
        "../scripts/train.py"


# The true-motion ceiling (a reference, not a method): the only training rule that reads
# truth.npz. No method, recovery or null result depends on it.
rule train_reference:
    input:
        observed=observed_input,
        truth=truth_input,
    output:
        ckpt=CKPT.replace("{config}", _models.BASE_CONFIG),
        loss=LOSS.replace("{config}", _models.BASE_CONFIG),
    log:
        "logs/train/{tree}/seed{seed}/{model}_single.log",
    benchmark:
        "results/benchmarks/train/{tree}/seed{seed}/{model}_single.tsv"
    wildcard_constraints:
        model="|".join(_models.REFERENCE_NAMES),
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=4000,
        runtime=10 + CFG["train"]["iterations"] // 60,
    params:
        job=lambda wc: _job_spec(
            CFG, wc.model, _models.BASE_CONFIG, seed=int(wc.seed), tree=wc.tree
        ),
    script:
        "../scripts/train_reference.py"


rule train_all:
    input:
        [
            CKPT.format(tree=t, seed=s, model=m, config=c)
            for t in TREES
            for s in SEEDS
            for m, c in TRAIN_JOBS
        ],
