"""Snakemake script of rule `search`: every search's trials in one CSV, the best recipes in one
YAML block for config/trees.yaml, and what each search found (which recipe stays)."""

from pathlib import Path

import pandas as pd

from physgs.experiments.search import summary
from physgs.jobs import job

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    trials = pd.concat([pd.read_csv(p) for p in sm.input.trials], ignore_index=True)
    trials.to_csv(sm.output.trials, index=False)
    text = "recipes:\n" + "".join(
        "".join(f"  {line}\n" for line in Path(p).read_text().splitlines())
        for p in sm.input.recipes
    )
    Path(sm.output.recipes).write_text(text)
    found = summary(trials, sm.params.adopt_above_db)
    Path(sm.output.summary).write_text(found.to_markdown(index=False, floatfmt=".2f") + "\n")
    print(f"{len(trials)} trials, {len(sm.input.recipes)} recipes", file=log)
