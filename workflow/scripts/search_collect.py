"""Snakemake script of rule `search`: every search's trials in one CSV, what each search found
(which recipe stays), and the recipes that replace the config's in one block for config/trees.yaml."""

from pathlib import Path

import pandas as pd

from physgs.experiments.search import recipes_block, summary
from physgs.jobs import job

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    trials = pd.concat([pd.read_csv(p) for p in sm.input.trials], ignore_index=True)
    trials.to_csv(sm.output.trials, index=False)
    found = summary(trials, sm.params.adopt_above_db)
    Path(sm.output.summary).write_text(found.to_markdown(index=False, floatfmt=".2f") + "\n")
    block = recipes_block([Path(p).read_text() for p in sm.input.recipes], found)
    Path(sm.output.recipes).write_text(block)
    print(f"{len(trials)} trials, {(found['recipe'] == 'searched').sum()} recipes kept", file=log)
