# K chosen from the data (issue 6): ours trained with K from held-out frames or BIC (`auto`),
# evaluated and scored like the fixed-K runs, and compared with K = 32 in tab_kselect.
# Include after train.smk, evaluate.smk, recovery.smk and report.smk (uses _build, _models).
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
    log:
        "logs/train/{tree}/ours_auto.log",
    benchmark:
        "results/benchmarks/train/{tree}/ours_auto.tsv"
    threads: 2
    resources:
        mem_mb=4000,
        runtime=10 + CFG["train"]["iterations"] // 60,
    script:
        "../scripts/train_auto.py"


rule evaluate_auto:
    input:
        ckpt="results/models/{tree}/ours_auto.pt",
        observed="results/testbed/{tree}/observed.npz",
        truth="results/testbed/{tree}/truth.npz",
    output:
        scores=_build.EVAL.replace("{model}_{config}", "ours_auto"),
        traj=_build.TRAJ.replace("{model}_{config}", "ours_auto"),
        panels=_build.PANELS.replace("{model}_{config}", "ours_auto"),
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
    params:
        backend=CFG["train"]["backend"],
    log:
        "logs/evaluate/{tree}/ours_auto.log",
    benchmark:
        "results/benchmarks/evaluate/{tree}/ours_auto.tsv"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=30,
    script:
        "../scripts/evaluate.py"


rule recovery_auto:
    input:
        ckpt="results/models/{tree}/ours_auto.pt",
        observed="results/testbed/{tree}/observed.npz",
        truth="results/testbed/{tree}/truth.npz",
    output:
        record=_build.RECOVERY.replace("{config}", "auto"),
    wildcard_constraints:
        tree="|".join(CFG["trees"]),
    log:
        "logs/recovery/{tree}/ours_auto.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    script:
        "../scripts/recovery.py"


rule tab_kselect:
    input:
        _ksel.inputs(TREES),
    output:
        tex="results/tables/tab_kselect.tex",
        csv="results/tables/tab_kselect.csv",
    params:
        cfg=CFG,
    log:
        "logs/report/tab_kselect.log",
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    script:
        "../scripts/kselect_table.py"
