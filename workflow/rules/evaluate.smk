# Evaluation (the protocol, section 4): every split of one trained model, scored through the rasterizer.
# Reads the ground truth only for branch-tip trajectories; never feeds anything back to training.


rule evaluate:
    input:
        ckpt=CKPT,
        observed=observed_input,
        truth=truth_input,
    output:
        scores=EVAL,
        traj=TRAJ,
        panels=PANELS,
    log:
        "logs/evaluate/{tree}/seed{seed}/{model}_{config}.log",
    benchmark:
        "results/benchmarks/evaluate/{tree}/seed{seed}/{model}_{config}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=30,
    params:
        backend=CFG["train"]["backend"],
        device=CFG["train"]["device"],
    script:
        "../scripts/evaluate.py"
