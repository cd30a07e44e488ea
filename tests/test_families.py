"""Model families (physgs.models.families): every registered id has a family that says what it
reads and builds it, so build_model and model_settings never branch on a family."""

from __future__ import annotations

import pytest

from physgs.models.families import FAMILIES, Family
from physgs.models.registry import (
    FIELD_FAMILIES,
    MODELS,
    PAPER_MODEL,
    PRIOR_VARIANTS,
    REFERENCES,
    model_settings,
)
from oracles import model_context, quick_models_cfg

ALL = {**MODELS, **PRIOR_VARIANTS, **REFERENCES}


@pytest.mark.parametrize("model", sorted(ALL))
def test_every_id_has_a_family_and_its_settings_are_canonical_first(model):
    spec = ALL[model]
    assert isinstance(FAMILIES[spec.family], Family)
    out = model_settings(quick_models_cfg(), model)
    assert next(iter(out)) == "canonical"


def test_the_derived_names_follow_the_specs():
    assert FIELD_FAMILIES == ("mlp", "d3dgs")
    assert PAPER_MODEL == "ours" and sum(s.paper for s in ALL.values()) == 1


def test_a_new_family_needs_only_its_entry(monkeypatch):
    """A family added to FAMILIES is built and read through it, with no other code."""
    from physgs.models import registry
    from physgs.models.registry import ModelSpec, build_model

    seen = {}

    def settings(cfg, model, spec):
        return {"toy": cfg["toy"]}

    def build(b):
        seen.update(name=b.name, K=b.K, section=b.cfg["toy"])
        return "built"

    monkeypatch.setitem(FAMILIES, "toy", Family(settings, build))
    monkeypatch.setitem(
        registry.PRIOR_VARIANTS, "toy_model", ModelSpec("T", "T", "toy", False, "control")
    )
    cfg = {**quick_models_cfg(), "toy": {"a": 1}}
    assert model_settings(cfg, "toy_model") == {"canonical": cfg["canonical"], "toy": {"a": 1}}
    ctx, _ = model_context(20, 0, 30)
    assert build_model("toy_model", ctx, cfg) == "built"
    assert seen == {"name": "toy_model", "K": None, "section": {"a": 1}}
