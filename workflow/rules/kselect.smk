# K chosen from the data (issue 6): ours trained with K from held-out frames or BIC (`auto`),
# evaluated and scored like the fixed-K runs, and compared with K = 32 in tab_kselect.
# Include after train.smk, evaluate.smk, recovery.smk and report.smk (uses _build, _models);
# ours_auto is evaluated and scored by the generic `evaluate` and `recovery` rules.
from physgs.report import kselect as _ksel

_KS = CFG["models"]["kselect"]


rule kselect:
    input:
        observed="results/testbed/{tree}/observed.npz",
    output:
        selection=_ksel.KSELECT,
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/kselect/{tree}.log",
    benchmark:
        "results/benchmarks/kselect/{tree}.tsv"
    threads: 2
    resources:
        mem_mb=4000,
        # minutes; about 1 s per iteration per candidate, generous for a cluster
        runtime=10 + len(_KS["candidates"]) * _KS["iterations"] // 60,
    script:
        "../scripts/kselect.py"


rule train_auto:
    input:
        observed="results/testbed/{tree}/observed.npz",
        selection=_ksel.KSELECT,
    output:
        ckpt="results/models/{tree}/ours_auto.pt",
        loss="results/models/{tree}/ours_auto.loss.csv",
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/train/{tree}/ours_auto.log",
    benchmark:
        "results/benchmarks/train/{tree}/ours_auto.tsv"
    threads: 1
    resources:
        mem_mb=4000,
        runtime=10 + CFG["train"]["iterations"] // 60,
    script:
        "../scripts/train_auto.py"


rule tab_kselect:
    input:
        _ksel.inputs(TREES),
    output:
        tex="results/tables/tab_kselect.tex",
        csv="results/tables/tab_kselect.csv",
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/report/tab_kselect.log",
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    script:
        "../scripts/kselect_table.py"
