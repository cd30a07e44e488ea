# The synthetic testbed (the protocol, section 1): per tree, the dataset (observed.npz for models,
# truth.npz for evaluation only) and a figure. `snakemake --cores 2 testbed` builds all trees.


rule testbed_dataset:
    output:
        observed=OBSERVED,
        truth=TRUTH,
    log:
        "logs/testbed/{tree}.log",
    benchmark:
        "results/benchmarks/testbed/{tree}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=20,
    params:
        settings=testbed_params,
    script:
        "../scripts/testbed_dataset.py"


rule testbed_stats:
    input:
        observed=OBSERVED,
        truth=TRUTH,
    output:
        stats=STATS,
    log:
        "logs/testbed/stats_{tree}.log",
    benchmark:
        "results/benchmarks/testbed/stats_{tree}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=10,
    script:
        "../scripts/testbed_stats.py"


# testbed_seeds: one instance per training seed, built by the same code with testbed seed {seed}
use rule testbed_dataset as testbed_dataset_seeded with:
    output:
        observed=SEEDED_OBSERVED,
        truth=SEEDED_TRUTH,
    log:
        "logs/testbed/{tree}_seed{seed}.log",
    benchmark:
        "results/benchmarks/testbed/{tree}_seed{seed}.tsv"


use rule testbed_stats as testbed_stats_seeded with:
    input:
        observed=SEEDED_OBSERVED,
        truth=SEEDED_TRUTH,
    output:
        stats=SEEDED_STATS,
    log:
        "logs/testbed/stats_{tree}_seed{seed}.log",
    benchmark:
        "results/benchmarks/testbed/stats_{tree}_seed{seed}.tsv"


rule testbed_figure:
    input:
        observed=OBSERVED,
        truth=TRUTH,
        stats=STATS,
    output:
        figure=report(
            "results/figures/testbed_{tree}.png",
            category="1. Testbed",
            labels={"tree": "{tree}"},
        ),
    log:
        "logs/testbed/figure_{tree}.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1500,
        runtime=5,
    script:
        "../scripts/testbed_figure.py"


rule testbed:
    input:
        expand(OBSERVED, tree=TESTBEDS),
        expand(TRUTH, tree=TESTBEDS),
        expand(STATS, tree=TESTBEDS),
        expand("results/figures/testbed_{tree}.png", tree=TESTBEDS),
        expand(TABLE, name="tab_testbed", ext=("tex", "csv")),
