"""Snakemake script of rule `search_recipe`: one model's recipe searched on one tree."""

from pathlib import Path

from physgs.experiments.search import SearchSettings, recipe_yaml, run_search
from physgs.jobs import job
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    trials, steps, best = run_search(
        load_observed(sm.input.observed),
        sm.params.job,
        SearchSettings.from_config(sm.params.search),
        tree=sm.wildcards.tree,
        log=lambda line: print(line, file=log, flush=True),
        # beside the outputs, not one: Snakemake removes a cut job's outputs, this file resumes it
        journal=sm.output.trials.replace(".trials.csv", ".journal"),
    )
    trials.to_csv(sm.output.trials, index=False)
    steps.to_csv(sm.output.steps, index=False)
    Path(sm.output.recipe).write_text(
        recipe_yaml(sm.wildcards.tree, sm.wildcards.model, trials, best)
    )
