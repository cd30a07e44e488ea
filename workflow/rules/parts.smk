# The parts study (docs/parts.md): the segmentations checked against the bones, and the chained
# prior at fewer parts than the base configuration (the smallest K matching ours).


# each prior's parts in the base configuration, their purity, pivots and parent links (reads
# truth.npz: an evaluation check)
rule parts_segmentation:
    input:
        unpack(parts_inputs),
    output:
        record=PARTS_RECORD,
    log:
        "logs/parts/{tree}/seed{seed}.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        models=PRIORS,
    script:
        "../scripts/parts_segmentation.py"


# the chained prior trained at a smaller K on the training frames minus every holdout_every-th,
# scored on those held-out frames (observed only: training-window data)
rule kmatch_point:
    input:
        observed=observed_input,
    output:
        point=KMATCH,
    log:
        "logs/parts/{tree}/seed{seed}_chain_K{K}.log",
    benchmark:
        "results/studies/benchmarks/kmatch/{tree}/seed{seed}_chain_K{K}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=4000,
        runtime=10 + CFG["train"]["iterations"] // 60,
    params:
        job=kmatch_params,
    script:
        "../scripts/kmatch_point.py"
