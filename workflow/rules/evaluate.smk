# Evaluation (SPEC section 4): every split of one trained model, scored through the rasterizer.
# Reads the ground truth only for branch-tip trajectories; never feeds anything back to training.

rule evaluate:
    input:
        ckpt="results/models/{tree}/{model}_{config}.pt",
        observed="results/testbed/{tree}/observed.npz",
        truth="results/testbed/{tree}/truth.npz",
    output:
        scores=_build.EVAL,
        traj=_build.TRAJ,
        panels=_build.PANELS,
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
        model="|".join(_models.MODEL_NAMES),
        config="|".join((*_models.CONFIG_NAMES, _models.AUTO_CONFIG)),
    params:
        backend=CFG["train"]["backend"],
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/evaluate/{tree}/{model}_{config}.log",
    benchmark:
        "results/benchmarks/evaluate/{tree}/{model}_{config}.tsv"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=30,
    script:
        "../scripts/evaluate.py"
