"""Model names, construction from the config, and checkpoints.

Two kinds of model id: the methods (``MODELS``, what every table iterates) and the references
(``REFERENCES``: ``truth_motion``, the ceiling, built from ``truth.npz`` and trained by its own
workflow rule). ``build_model``, ``model_settings``, ``label``, ``configs_for`` and
``load_checkpoint`` accept both; ``training_jobs`` lists the methods only.

A checkpoint (torch.save of plain dicts and tensors, loadable with weights_only=True) holds:
format, model name, training configuration name, seed, the ``models`` config section, the
``train`` config section, the ModelContext (canonical positions, fps, frame counts, frozen wind
statistics), the state dict and the training statistics.

The ids and labels import nothing heavy: the workflow reads them to plan jobs. The model classes
and torch load inside the functions that build, save or read a model.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from typing import TYPE_CHECKING, Iterable

import numpy as np

from physgs.atomic import atomic_path
from physgs.intermediate import remake_hint
from physgs.models.omega_search import OmegaSearch

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
    "ours": ModelSpec("Ours", "Ours", "ours", True, "prior"),
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


FIELDS = ("mlp", "d3dgs")  # learned deformation-field architectures
#: Every model is trained in this configuration; the priors also in every other one of the config.
BASE_CONFIG = "single"
#: the one configuration the forcing-free priors (``BLIND_PRIORS``) are trained in
BLIND_CONFIG = BASE_CONFIG
FORMAT = "physgs-model-v2"
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
    return spec_of(model).family == "ours"


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
        ``canonical`` and, as the model needs them, its family's section (its own
            ``time_top_hz`` only), ``topology``, ``blind``, ``omega_search`` (its own entry) and
            ``wind_window``.

    Raises:
        ValueError: for an unknown id.
    """
    spec = spec_of(model)
    out = {"canonical": models_cfg["canonical"]}
    if spec.family in REFERENCES:  # the canonical set only: the motion comes from truth.npz
        return out
    if spec.family != "static":
        out[spec.family] = models_cfg[spec.family]
    if spec.family in FIELDS:  # its own time scale only: a sibling field's edit leaves it alone
        section = models_cfg[spec.family]
        out[spec.family] = {**section, "time_top_hz": {model: section["time_top_hz"][model]}}
    if spec.parts == "topology":
        out["topology"] = models_cfg["topology"]
    if spec.forcing == "learned":
        out["blind"] = models_cfg["blind"]
    if searches_omega(models_cfg, model):  # its own entry only: another model's leaves it alone
        out["omega_search"] = {**models_cfg["omega_search"], "models": [model]}
    if spec.wind and spec.family in FIELDS:
        out["wind_window"] = models_cfg["wind_window"]
    return out


def searches_omega(models_cfg: dict, model: str) -> bool:
    """Whether ``model`` starts with the search over omega (``models.omega_search.models``;
    [`physgs.models.omega_search`][]).

    Args:
        models_cfg: the ``models`` config section.
        model: a model id.

    Returns:
        True when ``model`` is listed there.
    """
    return model in (models_cfg.get("omega_search") or {}).get("models", ())


def canonical_pose_of(topology_cfg: dict) -> str:
    """``models.topology.canonical_pose`` of a (possibly older) topology section: checkpoints
    written before the key existed carry ``from_frame0`` (true: ``frame0_angles``) or neither
    (``rest``).

    Args:
        topology_cfg: a ``models.topology`` section.

    Returns:
        ``'rest'``, ``'frame0_angles'`` or the section's own value.
    """
    if "canonical_pose" in topology_cfg:
        return str(topology_cfg["canonical_pose"])
    return "frame0_angles" if topology_cfg.get("from_frame0", False) else "rest"


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
    """A freshly initialised model.

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
    # here: the model classes load torch, and the workflow plans with this module (docstring)
    from physgs.models.base import ModelContext, context_from_observed
    from physgs.models.fields import FieldModel
    from physgs.models.ours import OscillatorPrior
    from physgs.models.static import StaticModel
    from physgs.models.truth_motion import TrueMotion, TruthMotionModel

    if not is_prior(name) and config != BASE_CONFIG:
        raise ValueError(
            f"model {name!r} is not trained in configuration {config!r}; valid: "
            f"('{BASE_CONFIG}',) (joint configurations are ours only)"
        )
    if truth is not None and not is_reference(name):
        raise ValueError(
            f"model {name!r} is a method: it may not read the ground truth "
            f"(truth.npz); only the references {REFERENCE_NAMES} do"
        )
    ctx = (  # a prior with a learned forcing never looks at the observed wind
        observed
        if isinstance(observed, ModelContext)
        else context_from_observed(observed, wind=spec_of(name).forcing == "wind")
    )
    canon = dict(cfg["canonical"])
    if is_reference(name):
        if truth is None:
            raise ValueError(
                f"the reference {name!r} moves the Gaussians by the ground truth: it "
                "needs the dataset's truth.npz (pass truth=load_truth(<tree>/"
                "truth.npz)); the dataset has no truth file or none was given"
            )
        if not isinstance(truth, TrueMotion):
            if isinstance(observed, ModelContext):
                raise ValueError(
                    f"building {name!r} from truth.npz needs the Observed dataset "
                    "(its per-condition winds), not a ModelContext"
                )
            truth = TrueMotion.from_truth(truth, observed)
        return TruthMotionModel(ctx, canon, truth)
    family = spec_of(name).family
    if family == "static":
        return StaticModel(ctx, canon)
    if family in FIELDS:
        a = cfg[family]
        ww = cfg["wind_window"] if MODELS[name].wind else {"seconds": None, "values": None}
        return FieldModel(
            ctx,
            canon,
            arch=family,
            pos_bands=a["pos_bands"],
            time_bands=a["time_bands"],
            depth=a["depth"],
            width=a["width"],
            skip=a.get("skip"),
            wind=MODELS[name].wind,
            window_seconds=ww["seconds"],
            window_values=ww["values"],
            name=name,
            precision=a.get("precision", "float32"),
            time_top_hz=a["time_top_hz"][name],
        )
    if K is None:
        spec = cfg.get("configs", {}).get(config)
        if spec is None:
            raise ValueError(
                f"ours has no configuration {config!r} and no K was given; valid: "
                f"{sorted(cfg.get('configs', {}))}"
            )
        K = spec["K"]
    o = cfg["ours"]
    spec = spec_of(name)
    options = {}
    if searches_omega(cfg, name):
        options["search"] = OmegaSearch.from_config(cfg["omega_search"])
    if spec.parts == "topology":
        t = cfg["topology"]
        options.update(
            segmentation="topology",
            knn=int(t["knn"]),
            parent=parent,
            canonical_pose=canonical_pose_of(t),
        )
    if spec.forcing == "learned":
        from physgs.models.blind import BlindOscillatorPrior  # here: torch, as above

        if options.get("search") is not None:
            raise ValueError(f"{name} has no search over omega: remove it from models/omega_search")
        cls = BlindOscillatorPrior
        options["forcing_hz"] = float(cfg["blind"]["forcing_hz"])
    else:
        cls = OscillatorPrior
    return cls(
        ctx,
        canon,
        K=int(K),
        omega_hz=o["omega_hz"],
        zeta=o["zeta"],
        omega_init_hz=o["omega_init_hz"],
        zeta_init=o["zeta_init"],
        substeps=o["substeps"],
        rk4_guard=o["rk4_guard"],
        kmeans_n_init=o["kmeans_n_init"],
        seed=seed,
        labels=labels,
        chain=spec.chain,
        **options,
    )


def save_checkpoint(
    path,
    model: BaseModel,
    *,
    name: str,
    config: str,
    seed: int,
    models_cfg: dict,
    train_cfg: dict,
    stats: dict,
) -> None:
    """Write the checkpoint atomically (temporary file in the same folder, then rename).

    Args:
        path (str | Path): the ``.pt`` file.
        model: the trained model.
        name: its model id.
        config: its training configuration name.
        seed: its training seed.
        models_cfg: the settings the model was built from
            ([`model_settings`][physgs.models.registry.model_settings] or the whole ``models``
            section); ours' K is read off the model, so any configuration name reloads.
        train_cfg: the ``train`` config section it was trained with.
        stats: the training statistics.
    """
    import torch  # here: the workflow plans with this module (module docstring)

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    blob = {
        "format": FORMAT,
        "model": name,
        "config": config,
        "seed": int(seed),
        "K": int(model.K) if hasattr(model, "K") else None,
        "models_cfg": models_cfg,
        "train_cfg": train_cfg,
        "context": model.ctx.to_dict(),
        "state_dict": _device_free(model.state_dict()),
        "stats": stats,
    }
    with atomic_path(path) as tmp:
        torch.save(blob, tmp)


def _device_free(sd):
    """``sd`` with its tensors on the CPU, so a model trained on a GPU reloads on any machine
    (``read_checkpoint`` maps to the CPU); a CPU model's state is returned as it is, so its file
    stays byte for byte what it was."""
    if all(v.device.type == "cpu" for v in sd.values()):
        return sd
    out = type(sd)((k, v.cpu()) for k, v in sd.items())
    out._metadata = getattr(sd, "_metadata", None)  # the modules' versions load_state_dict reads
    return out


def read_checkpoint(path) -> dict:
    """The raw checkpoint dict; clear errors for a missing or corrupt file.

    Args:
        path (str | Path): the ``.pt`` file.

    Returns:
        The checkpoint's dict (loaded on the CPU, ``weights_only``).

    Raises:
        FileNotFoundError: when there is no file.
        ValueError: when it does not unpickle or is not a checkpoint of this format.
    """
    import torch  # here: the workflow plans with this module (module docstring)

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(
            f"no checkpoint at {path}; train it first (snakemake --cores 2 {path})"
        )
    try:
        blob = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # noqa: BLE001 - any unpickling failure means a corrupt file
        raise ValueError(
            f"checkpoint {path} is corrupt or not a physgs checkpoint ({e}); to retrain it "
            f"{remake_hint(path).removeprefix('to remake it ')}"
        ) from None
    if not isinstance(blob, dict) or blob.get("format") != FORMAT:
        raise ValueError(
            f"{path} is not a {FORMAT} checkpoint; to retrain it "
            f"{remake_hint(path).removeprefix('to remake it ')}"
        )
    return blob


def load_checkpoint(path) -> BaseModel:
    """Rebuild the trained model (eval mode) from a checkpoint written by save_checkpoint.

    The returned model also carries ``checkpoint_info`` (name, config, seed, stats, cfgs).

    Args:
        path (str | Path): the ``.pt`` file.

    Returns:
        The model in eval mode, its state loaded strictly.

    Raises:
        FileNotFoundError: when there is no file.
        ValueError: for a corrupt checkpoint.
    """
    # here: torch, as in build_model
    from physgs.models.base import ModelContext
    from physgs.models.truth_motion import TrueMotion

    blob = read_checkpoint(path)
    sd = blob["state_dict"]
    labels = sd["part_labels"].numpy() if "part_labels" in sd else None
    parent = sd["part_parent"].numpy() if "part_parent" in sd else None
    # a reference's motion is in its own buffers: no truth.npz needed to reload it
    motion = TrueMotion.from_state_dict(sd) if is_reference(blob["model"]) else None
    # the checkpoint's state replaces the starting scales: no neighbour search (nor scipy)
    cfg = {**blob["models_cfg"], "canonical": {**blob["models_cfg"]["canonical"], "knn": None}}
    model = build_model(
        blob["model"],
        ModelContext.from_dict(blob["context"]),
        cfg,
        config=blob["config"],
        K=blob["K"],
        seed=blob["seed"],
        labels=labels,
        parent=parent,
        truth=motion,
    )
    model.load_state_dict(sd, strict=True)
    model.eval()
    model.checkpoint_info = {
        k: blob[k] for k in ("model", "config", "seed", "stats", "models_cfg", "train_cfg")
    }
    return model
