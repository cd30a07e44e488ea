# The speed-accuracy trade (SPEC section 5): one knob at a time away from the profile's settings,
# ours on one tree; `snakemake --cores 2 speed_accuracy`.
import physgs.speed_accuracy as _sa

SA_TREE = CFG["speed_accuracy"]["tree"]


rule speed_accuracy_point:
    input:
        observed=f"results/testbed/{SA_TREE}/observed.npz",
        truth=f"results/testbed/{SA_TREE}/truth.npz",
    output:
        record="results/speed_accuracy/{point}.json",
    wildcard_constraints:
        point="|".join(_sa.sweep_points(CFG)),
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/speed_accuracy/{point}.log",
    benchmark:
        "results/benchmarks/speed_accuracy/{point}.tsv"
    threads: 1  # two points run side by side on 2 cores (better throughput than 2 threads each)
    resources:
        mem_mb=4000,
        runtime=10 + CFG["train"]["iterations"] // 30,
    script:
        "../scripts/speed_accuracy_point.py"


rule speed_accuracy:
    input:
        expand("results/speed_accuracy/{point}.json", point=_sa.sweep_points(CFG)),
    output:
        csv="results/tables/speed_accuracy.csv",
        pdf="results/figures/fig_speed_accuracy.pdf",
        png="results/figures/fig_speed_accuracy.png",
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/speed_accuracy/collect.log",
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    script:
        "../scripts/speed_accuracy.py"
