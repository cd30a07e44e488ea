# Tables and figures. Each is a target of its own and declares exactly the files it reads, so
# `snakemake --cores 2 results/tables/tab_null.tex` trains ours and nothing else.
CONFIGS = list(CFG["models"]["configs"])


rule table:
    input:
        lambda wc: _build.inputs_for(wc.name, TREES, CONFIGS),
    output:
        tex="results/tables/{name}.tex",
        csv="results/tables/{name}.csv",
    wildcard_constraints:
        name="|".join(_build.TABLES),
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/report/{name}.log",
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    script:
        "../scripts/report_table.py"


rule figure:
    input:
        lambda wc: _build.inputs_for(wc.name, TREES, CONFIGS),
    output:
        pdf="results/figures/{name}.pdf",
        png="results/figures/{name}.png",
    wildcard_constraints:
        name="|".join(_build.FIGURES),
    params:
        cfg=CFG,
    conda:
        "../envs/physgs.yaml"
    log:
        "logs/report/{name}.log",
    threads: 1
    resources:
        mem_mb=1500,
        runtime=5,
    script:
        "../scripts/report_figure.py"


rule report:
    input:
        expand("results/tables/{name}.{ext}", name=_build.TABLES, ext=("tex", "csv")),
        expand("results/figures/{name}.{ext}", name=_build.FIGURES, ext=("pdf", "png")),
