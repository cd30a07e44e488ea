# Tables and figures. Each is a target of its own and declares exactly the files it reads (need
# tuples of physgs.report.build, mapped to paths in common.smk), so
# `snakemake --cores 2 results/tables/tab_null.tex` trains ours and nothing else.


rule table:
    input:
        unpack(report_inputs),
    output:
        tex=TABLE.replace("{ext}", "tex"),
        csv=report(TABLE.replace("{ext}", "csv"), category="3. Tables", labels={"table": "{name}"}),
    log:
        "logs/report/{name}.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        settings=report_params,
        stamp=STAMP,
    script:
        "../scripts/report_table.py"


rule figure:
    input:
        unpack(report_inputs),
    output:
        pdf=FIGURE.replace("{ext}", "pdf"),
        png=report(
            FIGURE.replace("{ext}", "png"), category="2. Results", labels={"figure": "{name}"}
        ),
    log:
        "logs/report/{name}.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1500,
        runtime=5,
    params:
        settings=report_params,
    script:
        "../scripts/report_figure.py"


rule report:
    input:
        expand(
            TABLE,
            ext=("tex", "csv"),
            name=[n for n in _build.TABLES if _build.in_report(n, REPORT_PLAN)],
        ),
        expand(
            FIGURE,
            name=[f for f in _build.FIGURES if _build.in_report(f, REPORT_PLAN)],
            ext=("pdf", "png"),
        ),
        parts_jobs(),


# The claims ledger: every claim of the catalogue (physgs.report.catalogue) with its measured
# value, seed interval and a verdict computed by code (physgs.report.claims); the tables it reads
# are the catalogue's. The script gets the need tuples too: the ledger reads by tuple, never by
# a name split apart again.
CLAIMS_NEEDS = _build.claims_needs(REPORT_PLAN)


rule claims:
    input:
        unpack(lambda wc: need_paths(CLAIMS_NEEDS)),
    output:
        md=report("results/claims.md", category="5. Claims"),
        csv="results/claims.csv",
    log:
        "logs/report/claims.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        trees=TREES,
        stamp=STAMP,
        roles=_claim_cells.roles_of(CFG["presets"], TREES),
        needs=CLAIMS_NEEDS,
    script:
        "../scripts/claims.py"
