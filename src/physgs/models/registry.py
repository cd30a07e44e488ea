"""Model ids and what each is: the planning data the workflow reads, and the one way to build one.

Two kinds of model id: the methods (``MODELS``, what every table iterates; ``PRIOR_VARIANTS``,
the oscillator priors studied beside them) and the references (``REFERENCES``: ``truth_motion``,
the ceiling, built from ``truth.npz`` and trained by its own workflow rule). Each id's
[`ModelSpec`][physgs.models.registry.ModelSpec] names its family (``family``: its section under
``models:``), and [`FAMILIES`][physgs.models.families.FAMILIES] says what that family reads
(``model_settings``) and builds it (``build_model``). ``build_model``, ``model_settings``,
``label``, ``configs_for`` and the checkpoints ([`physgs.models.checkpoint`][]) accept every id;
``training_jobs`` lists the methods only.

The ids, labels and settings import nothing heavy: the workflow reads them to plan jobs. The
model classes and torch load when a model is built.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Iterable

import numpy as np

from physgs.models.families import FAMILIES, Build

if TYPE_CHECKING:  # the model classes load torch (module docstring)
    from physgs.models.base import BaseModel


@dataclass(frozen=True)
class ModelSpec:
    """One model id: its table label, its short column head, what settings it reads."""

    label: str  # full name in tables and figure legends
    short: str  # column head under a family heading (tab_transfer)
    family: str  # config section of its architecture ("static", "mlp", "d3dgs", "ours")
    wind: bool  # reads the observed wind
    role: str  # what it is in the comparison (``ROLES``): which tables' rows it joins
    parts: str = "kmeans"  # oscillator priors: how parts are cut ("kmeans" or "topology")
    chain: bool = False  # oscillator priors: each part's transform composed with its parent's
    forcing: str = "wind"  # oscillator priors: "wind" (measured) or "learned" (physgs.models.blind)
    # a forcing-free prior: the prior of ``MODELS`` whose measured wind it replaces (the
    # ledger's anemometer claim compares the two)
    blind_of: str | None = None
    # the paper's method (ours): the prior the others vary, whose K the K selection's own keys
    # choose (``PAPER_MODEL``)
    paper: bool = False


#: The roles a model plays in the comparison. A report output (``physgs.report.outputs``) declares
#: the roles it reads and gets every model of those roles (``models_of``), in registry order:
#: control (the static pose: no motion), field (a learned deformation field), prior (an
#: oscillator prior: trained in every configuration, scored on recovery against the null),
#: reference (not a method: the true-motion ceiling). The untrained null is no model: it is the
#: recovery tables' own control, drawn per K (``physgs.recovery.null``).
ROLES = ("control", "field", "prior", "reference")

#: The one source of model ids and labels; order = row order of every table.
MODELS: dict[str, ModelSpec] = {
    "static": ModelSpec("Static pose", "Static", "static", False, "control"),
    "mlp": ModelSpec("Deformation MLP", "no wind", "mlp", False, "field"),
    "mlp_wind": ModelSpec("Deformation MLP + wind", r"+\,wind", "mlp", True, "field"),
    "d3dgs": ModelSpec("Deformable-3DGS", "no wind", "d3dgs", False, "field"),
    "d3dgs_wind": ModelSpec("Deformable-3DGS + wind", r"+\,wind", "d3dgs", True, "field"),
    "ours": ModelSpec("Ours", "Ours", "ours", True, "prior", paper=True),
    # this project's prior, not the paper's : parts cut along the tree, each
    # part's transform composed with its parent's, omega searched before the descent
    "ours_chain": ModelSpec(
        "Chained prior (this project)",
        "Chained",
        "ours",
        True,
        "prior",
        parts="topology",
        chain=True,
    ),
}
MODEL_NAMES = tuple(MODELS)
#: the paper's method (``ModelSpec.paper``): the prior every other prior varies
PAPER_MODEL = next(m for m, s in MODELS.items() if s.paper)
#: Variants of the oscillator prior studied beside ours in tab_parts only:
#: topology-aware parts (physgs.models.topology) without the chain. Ids of their own, not
#: options of ``ours``, so one run can train them side by side under one recipe (``job_spec``/
#: ``fit`` treat every model of family "ours" alike). Kept out of MODELS: every table and the
#: job plan iterate MODELS (the chained variant is one of them).
PRIOR_VARIANTS: dict[str, ModelSpec] = {
    "ours_topo": ModelSpec(
        "Ours, topology parts", "topology", "ours", True, "prior", parts="topology"
    ),
    # ours with a learned forcing shared by every part instead of the measured wind
    # (physgs.models.blind); trained in `single` only (one window, one forcing)
    "ours_blind": ModelSpec(
        "Ours, learned forcing",
        "blind",
        "ours",
        False,
        "prior",
        forcing="learned",
        blind_of="ours",
    ),
    "ours_chain_blind": ModelSpec(
        "Ours, chained topology parts, learned forcing",
        "chained, blind",
        "ours",
        False,
        "prior",
        parts="topology",
        chain=True,
        forcing="learned",
        blind_of="ours_chain",
    ),
}
PRIOR_VARIANT_NAMES = tuple(PRIOR_VARIANTS)
#: the forcing-free priors (docs/blind.md): trained in ``BLIND_CONFIG`` only (one window,
#: one forcing), scored in tab_fit, tab_null and tab_damping beside ours
BLIND_PRIORS = tuple(m for m, s in PRIOR_VARIANTS.items() if s.forcing == "learned")
#: Reference models: not methods (no recovery, null or method result depends on them), so kept
#: out of MODELS / MODEL_NAMES. truth_motion moves the canonical Gaussians by the ground-truth
#: skinning (physgs.models.truth_motion): the ceiling; the only model that reads truth.npz.
REFERENCES: dict[str, ModelSpec] = {
    "truth_motion": ModelSpec(
        "True motion (ceiling)", "True motion", "truth_motion", True, "reference"
    ),
}
REFERENCE_NAMES = tuple(REFERENCES)


def models_of(*roles: str) -> tuple[str, ...]:
    """The ids of the methods (``MODELS``) and references of the given roles (``ROLES``), in
    registry order (methods first): what a table reads when it reads those roles (the study
    variants, ``PRIOR_VARIANTS``, are not among them).

    Args:
        *roles: role names from ``ROLES``.

    Returns:
        The model ids whose role is among ``roles``.

    Raises:
        ValueError: for a role not in ``ROLES``.
    """
    bad = [r for r in roles if r not in ROLES]
    if bad:
        raise ValueError(f"unknown model role(s) {bad}; choose from {ROLES}")
    return tuple(m for m, s in (*MODELS.items(), *REFERENCES.items()) if s.role in roles)


#: the learned deformation-field architectures: the families of the ``field`` models
FIELD_FAMILIES = tuple(dict.fromkeys(s.family for s in MODELS.values() if s.role == "field"))
#: Every model is trained in this configuration; the priors also in every other one of the config.
BASE_CONFIG = "single"
#: the one configuration the forcing-free priors (``BLIND_PRIORS``) are trained in
BLIND_CONFIG = BASE_CONFIG
#: Ours with K chosen from the data (physgs.experiments.kselect); its K is passed explicitly.
AUTO_CONFIG = "auto"


def blind_priors(configs: Iterable[str]) -> tuple[str, ...]:
    """The forcing-free priors (``BLIND_PRIORS``) trained with the configurations ``configs``:
    all of them when ``BLIND_CONFIG`` is among them, none otherwise.

    Args:
        configs (Iterable[str]): configuration names (a run's ``models.configs``, or a
            table's own).

    Returns:
        tuple[str, ...]: their ids, in registry order.
    """
    return BLIND_PRIORS if BLIND_CONFIG in configs else ()


@dataclass(frozen=True)
class RecoveryMethod:
    """One method that recovers omega and zeta, scored on recovery against the untrained null of
    its K (tab_null, tab_recovery, tab_damping). Its record is ``results/recovery/<testbed>/
    seed<seed>/<id>_<config>.json`` (ours' format, ``physgs.recovery.record``), written by the
    workflow rule ``rule``: adding a method is one entry here plus the rules that write it.

    label: its rows' LaTeX name; None: the model's registry label (``label``); "": none, its
    rows are labelled by their configuration alone (ours: the paper's). rule: the workflow rule
    that writes its record. section: the config section that lists its configurations and K
    (``<section>.configs`` and ``<section>.K``: ``same`` for each configuration's own K, or an
    integer); None: a trained prior, in the configurations it is trained in (``configs_for``),
    each with its K. note: its sentence in the recovery tables' captions, after '<label>: '
    ("" none). damping_note: tab_damping's sentence, where it differs (None: ``note``). paper:
    the paper's method (tab_null's rows)."""

    label: str | None
    rule: str
    section: str | None = None
    note: str = ""
    damping_note: str | None = None
    paper: bool = False


#: the caption sentence of a prior beside ours (scored like ours)
_PRIOR_NOTE = (
    r"the same scoring of its own parts, beside the null of its $K$ (a null depends on $K$ only)."
)
#: the caption sentence of a forcing-free prior (``BLIND_PRIORS``)
_BLIND_NOTE = (
    "the measured wind replaced by a forcing learned from the training video (trained "
    r"in its configuration only), beside the null of its $K$."
)
#: The one list of recovery methods; order = row order of every recovery table.
RECOVERY_METHODS: dict[str, RecoveryMethod] = {
    "ours": RecoveryMethod("", "recovery", paper=True),
    "ours_chain": RecoveryMethod(None, "recovery", note=_PRIOR_NOTE, damping_note=""),
    # the 2D-track control (physgs.tracks): ours' oscillators fitted to point tracks
    "tracks": RecoveryMethod(
        r"\emph{2D tracks}",
        "tracks_evaluate",
        section="tracks",
        note=(
            r"the same oscillators fitted to point tracks of the training "
            r"video (no renderer), matched and trusted by the same rule, beside the null of its "
            r"$K$; a part with too few tracks has no estimate and is never trusted."
        ),
        damping_note=(
            r"the same oscillators fitted to point tracks of the training "
            r"video (no renderer), scored on its own matching against its own null draw."
        ),
    ),
    # the output-only modal analysis of the training video (physgs.oma)
    "oma": RecoveryMethod(
        r"\emph{Output-only (SSI)}",
        "oma_recovery",
        section="oma",
        note=(
            r"modes identified from the training video alone (dense flow, SSI-cov; "
            r"no wind, no renderer), each assigned to a part by its shape, matched and trusted by "
            r"the same rule, beside the null of its $K$. Its seeds resample only the $k$-means of "
            r"image cells into parts (the same video, so the same modes, at every seed): its seed "
            r"intervals understate what another tree instance would do. The CSV gives the "
            r"coverage of its modes' 95\% intervals ($\pm1.96\sigma$) over the trusted parts and "
            r"the parts its own rule keeps (relative $\sigma_\zeta\le1/1.96$)."
        ),
    ),
    **{m: RecoveryMethod(None, "recovery", note=_BLIND_NOTE) for m in BLIND_PRIORS},
}
RECOVERY_METHOD_NAMES = tuple(RECOVERY_METHODS)
#: ``<section>.K`` value meaning "the configuration's own K" (``models.configs.<c>.K``)
SAME_K = "same"


def section_k(cfg: dict, section: str, config: str) -> int:
    """K of a method with a config section of its own (``tracks``, ``oma``) in ``config``.

    Args:
        cfg: the resolved config.
        section: the method's config section (``RecoveryMethod.section``).
        config: a configuration name of ``models.configs``.

    Returns:
        ``<section>.K``, or the configuration's own K where that is ``same`` (or absent).
    """
    k = cfg[section].get("K", SAME_K)
    return int(cfg["models"]["configs"][config]["K"]) if k == SAME_K else int(k)


def recovery_configs(method: str, cfg: dict) -> dict[str, int]:
    """The configurations a recovery method runs in, each with its K.

    Args:
        method: a recovery method's id (``RECOVERY_METHODS``).
        cfg: the resolved config (``models.configs`` and the method's section).

    Returns:
        configuration -> K, in the order its section (or ``models.configs``) lists them; {} when
            it runs in none.

    Raises:
        ValueError: for an id not in ``RECOVERY_METHODS``.
    """
    if method not in RECOVERY_METHODS:
        raise ValueError(
            f"unknown recovery method {method!r}; choose one of {RECOVERY_METHOD_NAMES}"
        )
    mc = cfg["models"]["configs"]
    section = RECOVERY_METHODS[method].section
    if section is None:
        return {c: int(mc[c]["K"]) for c in configs_for(method, mc) if c in mc}
    return {c: section_k(cfg, section, c) for c in cfg[section]["configs"]}


def recovery_plan(cfg: dict) -> dict[str, dict[str, int]]:
    """Every recovery method the run scores, with its configurations and their K.

    Args:
        cfg: the resolved config.

    Returns:
        method id -> ``recovery_configs``, in ``RECOVERY_METHODS`` order; a method that runs in
            no configuration is left out.
    """
    out = {m: recovery_configs(m, cfg) for m in RECOVERY_METHODS}
    return {m: v for m, v in out.items() if v}


def recovery_label(method: str) -> str:
    """The LaTeX name of a recovery method's rows (``RecoveryMethod.label``).

    Args:
        method: a recovery method's id.

    Returns:
        Its label ("" for the paper's method, labelled by configuration alone).
    """
    own = RECOVERY_METHODS[method].label
    return label(method) if own is None else own


def is_reference(model: str) -> bool:
    """Whether ``model`` is a reference id (``REFERENCES``), not a method.

    Args:
        model: a model id.

    Returns:
        True for a reference id.
    """
    return model in REFERENCES


def spec_of(model: str) -> ModelSpec:
    """The ModelSpec of a method, prior variant or reference id (ValueError naming the ids).

    Args:
        model: a method, prior variant or reference id.

    Returns:
        Its [`ModelSpec`][physgs.models.registry.ModelSpec].

    Raises:
        ValueError: for an unknown id, naming the valid ones.
    """
    spec = MODELS.get(model) or PRIOR_VARIANTS.get(model) or REFERENCES.get(model)
    if spec is None:
        raise ValueError(
            f"unknown model {model!r}; choose one of {MODEL_NAMES}, a prior variant "
            f"{PRIOR_VARIANT_NAMES} or a reference {REFERENCE_NAMES}"
        )
    return spec


def is_prior(model: str) -> bool:
    """Whether ``model`` is an oscillator prior (``ours`` or one of PRIOR_VARIANTS): trained in
    every configuration, with K parts, part freezing and recovery.

    Args:
        model: a model id.

    Returns:
        True for an oscillator prior.

    Raises:
        ValueError: for an unknown id.
    """
    return spec_of(model).role == "prior"


def label(model: str) -> str:
    """Table/legend label of a model id (method or reference).

    Args:
        model: a model id.

    Returns:
        Its label, or ``model`` itself for an unknown id.
    """
    spec = MODELS.get(model) or PRIOR_VARIANTS.get(model) or REFERENCES.get(model)
    return spec.label if spec is not None else model


def config_label(name: str, spec: dict, tex: bool = True) -> str:
    """'single ($K{=}32$)' / 'joint ($K{=}96$)': derived from the configuration's conditions and K.

    Args:
        name: the configuration's name (unused: the label is derived from ``spec``).
        spec: the configuration (``conditions`` and ``K``).
        tex: LaTeX math for K (tables) or plain text.

    Returns:
        The label.
    """
    kind = "single" if spec["conditions"] == "train" else "joint"
    return rf"{kind} ($K{{=}}{int(spec['K'])}$)" if tex else f"{kind} (K={int(spec['K'])})"


def condition_indices(spec: str, n_conditions: int) -> list[int]:
    """Wind conditions a configuration trains on: 'train' -> [0], 'all' -> every condition.

    Args:
        spec: ``'train'`` or ``'all'`` (a configuration's ``conditions``).
        n_conditions: the dataset's condition count.

    Returns:
        The condition indices.

    Raises:
        ValueError: for any other ``spec``.
    """
    if spec == "train":
        return [0]
    if spec == "all":
        return list(range(n_conditions))
    raise ValueError(f"unknown conditions {spec!r} in models.configs; use 'train' or 'all'")


def configs_for(model: str, configs) -> tuple[str, ...]:
    """Configurations a model is trained in: every model (references too) `single`, ours (and
    its wind-driven variants) every configuration; a prior with a learned forcing `single`
    only (one training window, one forcing).

    Args:
        model: a model id.
        configs (Iterable[str]): the names of the config's ``models.configs`` (the one source of
            configurations).

    Returns:
        The configuration names, in ``configs``' order.

    Raises:
        ValueError: for an unknown id.
    """
    if is_prior(model) and spec_of(model).forcing == "wind":
        return tuple(configs)
    return (BASE_CONFIG,)


def training_jobs(configs) -> list[tuple[str, str]]:
    """All (model, configuration) pairs trained per tree, for the config's ``models.configs``
    (methods only: references have their own workflow rule).

    Args:
        configs (Iterable[str]): the names of ``models.configs``.

    Returns:
        ``(model, configuration)`` pairs, models in ``MODEL_NAMES`` order.
    """
    return [(m, c) for m in MODEL_NAMES for c in configs_for(m, configs)]


def model_settings(models_cfg: dict, model: str) -> dict:
    """The part of the ``models`` config section that ``model`` reads (and nothing else), so a
    workflow job is out of date only when one of its own settings changes.

    Args:
        models_cfg: the ``models`` config section.
        model: a model id.

    Returns:
        ``canonical`` and what its family reads (``Family.settings``): a field's section with its
            own ``time_top_hz`` only and the ``wind_window`` when it reads the wind; a prior's
            section, ``topology``, ``blind`` and ``omega_search`` (its own entry) as it needs
            them; nothing more for the static pose and the references.

    Raises:
        ValueError: for an unknown id.
    """
    spec = spec_of(model)
    return {
        "canonical": models_cfg["canonical"],
        **FAMILIES[spec.family].settings(models_cfg, model, spec),
    }


def build_model(
    name: str,
    observed,
    cfg: dict,
    *,
    config: str = BASE_CONFIG,
    K: int | None = None,
    seed: int = 0,
    labels: np.ndarray | None = None,
    parent: np.ndarray | None = None,
    truth=None,
) -> BaseModel:
    """A freshly initialised model, built by its family (``FAMILIES[spec.family].build``).

    A method given a truth raises (methods never read it).

    Args:
        name: one of MODEL_NAMES, PRIOR_VARIANT_NAMES or REFERENCE_NAMES.
        observed (Observed | ModelContext): a testbed
            [`Observed`][physgs.testbed.dataset.Observed] or a
            [`ModelContext`][physgs.models.base.ModelContext].
        cfg: the ``models`` config section, or
            [`model_settings`][physgs.models.registry.model_settings] of it.
        config: training configuration name.
        K: number of parts of ours (default: ``cfg['configs'][config]['K']``).
        seed: k-means seed (ours).
        labels: precomputed part labels [N] (used when loading).
        parent: precomputed part parents [K] (topology variants; used when loading).
        truth (Truth | TrueMotion | None): references only, and required by them: the dataset's
            [`Truth`][physgs.testbed.dataset.Truth] (``load_truth`` of truth.npz; ``observed``
            must then be the ``Observed``), or the ``TrueMotion`` a checkpoint stores.

    Returns:
        The model, untrained: a truth-motion reference, the static model, a field model or an
            oscillator prior (blind for a learned forcing).

    Raises:
        ValueError: for a model not trained in ``config``, a method given a truth, a reference
            without one (or built from truth.npz with a ModelContext), a configuration ours does
            not have when K is not given, or a learned-forcing prior listed for the search over
            omega.
    """
    # here: the context loads torch, and the workflow plans with this module (docstring)
    from physgs.models.base import ModelContext, context_from_observed

    spec = spec_of(name)
    if spec.role != "prior" and config != BASE_CONFIG:
        raise ValueError(
            f"model {name!r} is not trained in configuration {config!r}; valid: "
            f"('{BASE_CONFIG}',) (joint configurations are ours only)"
        )
    if truth is not None and spec.role != "reference":
        raise ValueError(
            f"model {name!r} is a method: it may not read the ground truth "
            f"(truth.npz); only the references {REFERENCE_NAMES} do"
        )
    ctx = (  # a prior with a learned forcing never looks at the observed wind
        observed
        if isinstance(observed, ModelContext)
        else context_from_observed(observed, wind=spec.forcing == "wind")
    )
    request = Build(
        name,
        spec,
        ctx,
        dict(cfg["canonical"]),
        cfg,
        observed,
        config,
        K,
        seed,
        labels,
        parent,
        truth,
    )
    return FAMILIES[spec.family].build(request)
