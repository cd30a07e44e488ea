# The recipe search (issue "Opponents that fit"): each model's learning rates, size and time
# encoding chosen per tree on its held-out window frames (physgs.experiments.search). Outside
# `all`: `snakemake --cores 2 search`; the chosen recipes go to config/trees.yaml (recipes) by
# hand, with the evidence (docs/search.md).


rule search_recipe:
    input:
        observed=OBSERVED,
    output:
        trials=SEARCH.replace("{what}", "trials.csv"),
        steps=SEARCH.replace("{what}", "steps.csv"),
        recipe=SEARCH.replace("{what}", "recipe.yaml"),
    log:
        "logs/search/{tree}/{model}.log",
    benchmark:
        "results/studies/benchmarks/search/{tree}/{model}.tsv"
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=4000,
        # minutes: every trial at the job's full budget (pruned ones end sooner)
        runtime=lambda wc: CFG["search"]["trials"]
        * (10 + search_job(wc)["train"]["iterations"] // 60),
    params:
        job=search_job,
        search=lambda wc: {
            k: CFG["search"][k] for k in ("trials", "every", "startup", "seed", "prune_after")
        },
    script:
        "../scripts/search.py"


rule search:
    input:
        trials=expand(
            SEARCH,
            tree=CFG["search"].get("trees", TREES),
            model=CFG["search"]["models"],
            what="trials.csv",
        ),
        recipes=expand(
            SEARCH,
            tree=CFG["search"].get("trees", TREES),
            model=CFG["search"]["models"],
            what="recipe.yaml",
        ),
    output:
        trials="results/search/trials.csv",
        recipes="results/search/recipes.yaml",
        summary="results/search/summary.md",
    log:
        "logs/search/collect.log",
    conda:
        "../envs/physgs.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        adopt_above_db=CFG["search"]["adopt_above_db"],
    script:
        "../scripts/search_collect.py"
