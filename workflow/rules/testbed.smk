# The synthetic testbed (SPEC section 1): per tree, the dataset (observed.npz for models,
# truth.npz for evaluation only) and a figure. `snakemake --cores 2 testbed` builds all trees.


rule testbed_dataset:
    output:
        observed="results/testbed/{tree}/observed.npz",
        truth="results/testbed/{tree}/truth.npz",
    params:
        testbed=CFG["testbed"],
        preset=lambda wc: CFG["presets"][wc.tree],
        seed=CFG["seed"],
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/testbed/{tree}.log",
    benchmark:
        "results/benchmarks/testbed/{tree}.tsv"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=20,
    wildcard_constraints:
        tree="sparse|medium|dense",
    script:
        "../scripts/testbed_dataset.py"


rule testbed_figure:
    input:
        observed="results/testbed/{tree}/observed.npz",
        truth="results/testbed/{tree}/truth.npz",
    output:
        figure="results/figures/testbed_{tree}.png",
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/testbed/figure_{tree}.log",
    threads: 1
    resources:
        mem_mb=1500,
        runtime=5,
    wildcard_constraints:
        tree="sparse|medium|dense",
    script:
        "../scripts/testbed_figure.py"


rule testbed:
    input:
        expand("results/testbed/{tree}/observed.npz", tree=TREES),
        expand("results/testbed/{tree}/truth.npz", tree=TREES),
        expand("results/figures/testbed_{tree}.png", tree=TREES),
