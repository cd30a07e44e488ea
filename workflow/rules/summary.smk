# results/summary.md: what the finished run says (stamp, the ledger's verdicts, tab_fit's
# fractions, wall time and job-minutes by stage), printed from the run's own files by
# physgs.report.summary. It reads every benchmark file under results/benchmarks/, so it waits for
# everything `all` makes (RUN, in the Snakefile); always rerun with the run, since the benchmark
# files are not outputs. The studies' own jobs keep theirs apart (results/studies/benchmarks/):
# a `studies` run in the same folder adds nothing to the summary of `all`.


rule summary:
    input:
        claims="results/claims.csv",
        tab_fit=TABLE.format(name="tab_fit", ext="csv"),
        run=RUN,
    output:
        report("results/summary.md", category="0. Summary"),
    log:
        "logs/report/summary.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        stamp=STAMP,
        benchmarks="results/benchmarks",
    script:
        "../scripts/summary.py"
