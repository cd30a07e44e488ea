"""Model families: each one spec that says what its models read and builds them.

A family is the architecture behind one or more model ids (``ModelSpec.family``, the name of its
section under ``models:``). [`FAMILIES`][physgs.models.families.FAMILIES] maps each name to a
[`Family`][physgs.models.families.Family]: its ``settings`` (the part of the ``models`` section
its models read beyond the canonical set, so a job reruns only when one of them changes) and its
``build`` (a fresh model). [`build_model`][physgs.models.registry.build_model] and
[`model_settings`][physgs.models.registry.model_settings] look the family up and call it; neither
branches on a family. Adding a family is its entry here (its settings and its builder), its
models' entries in the registry, and its config section (``config/trees.yaml`` and the schema).

Importing this module loads no torch (the workflow plans with the registry, which imports it):
each builder imports its model class when it is called.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from physgs.models.omega_search import OmegaSearch

if TYPE_CHECKING:  # the model classes load torch (module docstring)
    from physgs.models.base import BaseModel, ModelContext
    from physgs.models.registry import ModelSpec

#: ours' oscillator settings (``models.ours``) that build its oscillators, the one list of them:
#: the prior's keyword arguments and the 2D-track control's params
#: ([`physgs.tracks.settings`][]) both read exactly these
OSCILLATOR_KEYS = ("omega_hz", "zeta", "omega_init_hz", "zeta_init", "substeps", "rk4_guard")


@dataclass(frozen=True)
class Build:
    """What a family's builder reads: one call of ``build_model``, checked and resolved.

    name: the model id; spec: its registry entry; ctx: the observed-dataset facts it is built
    from; canonical: the canonical set's settings (``models.canonical``); cfg: the ``models``
    settings; observed: what ``build_model`` was given (an ``Observed`` or a ``ModelContext``);
    config: the training configuration; K, seed, labels [N], parent [K]: the parts' options (the
    oscillator priors'); truth: a reference's ground truth (None for a method).
    """

    name: str
    spec: ModelSpec
    ctx: ModelContext
    canonical: dict
    cfg: dict
    observed: Any
    config: str
    K: int | None = None
    seed: int = 0
    labels: np.ndarray | None = None
    parent: np.ndarray | None = None
    truth: Any = None


@dataclass(frozen=True)
class Family:
    """One model family: the settings its models read and how one is built.

    settings: ``(models section, model id, spec) -> {key: settings}``, what the model reads
    beyond ``canonical``, in the order its checkpoint stores them; build: ``Build -> model``.
    """

    settings: Callable[[dict, str, ModelSpec], dict]
    build: Callable[[Build], BaseModel]


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


# --- the canonical set alone: the static pose, the true motion --------------------------------


def _no_settings(models_cfg: dict, model: str, spec: ModelSpec) -> dict:
    """Nothing beyond the canonical set."""
    return {}


def _build_static(b: Build) -> BaseModel:
    """The Gaussians frozen at their canonical pose."""
    from physgs.models.static import StaticModel  # here: torch (module docstring)

    return StaticModel(b.ctx, b.canonical)


def _build_true_motion(b: Build) -> BaseModel:
    """The canonical Gaussians moved by the ground-truth skinning (the ceiling).

    Raises:
        ValueError: no truth was given, or truth.npz with a ModelContext (it needs the winds).
    """
    from physgs.models.base import ModelContext  # here: torch (module docstring)
    from physgs.models.truth_motion import TrueMotion, TruthMotionModel

    truth = b.truth
    if truth is None:
        raise ValueError(
            f"the reference {b.name!r} moves the Gaussians by the ground truth: it "
            "needs the dataset's truth.npz (pass truth=load_truth(<tree>/"
            "truth.npz)); the dataset has no truth file or none was given"
        )
    if not isinstance(truth, TrueMotion):
        if isinstance(b.observed, ModelContext):
            raise ValueError(
                f"building {b.name!r} from truth.npz needs the Observed dataset "
                "(its per-condition winds), not a ModelContext"
            )
        truth = TrueMotion.from_truth(truth, b.observed)
    return TruthMotionModel(b.ctx, b.canonical, truth)


# --- the learned deformation fields ------------------------------------------------------------


def _field_settings(models_cfg: dict, model: str, spec: ModelSpec) -> dict:
    """Its architecture's section with its own time scale only (a sibling field's edit leaves it
    alone), and the wind window when it reads the wind."""
    section = models_cfg[spec.family]
    out = {spec.family: {**section, "time_top_hz": {model: section["time_top_hz"][model]}}}
    if spec.wind:
        out["wind_window"] = models_cfg["wind_window"]
    return out


def _build_field(b: Build) -> BaseModel:
    """A learned deformation field of the family's architecture."""
    from physgs.models.fields import FieldModel  # here: torch (module docstring)

    a = b.cfg[b.spec.family]
    ww = b.cfg["wind_window"] if b.spec.wind else {"seconds": None, "values": None}
    return FieldModel(
        b.ctx,
        b.canonical,
        arch=b.spec.family,
        pos_bands=a["pos_bands"],
        time_bands=a["time_bands"],
        depth=a["depth"],
        width=a["width"],
        skip=a.get("skip"),
        wind=b.spec.wind,
        window_seconds=ww["seconds"],
        window_values=ww["values"],
        name=b.name,
        precision=a.get("precision", "float32"),
        time_top_hz=a["time_top_hz"][b.name],
    )


# --- the oscillator priors -------------------------------------------------------------------


def _prior_settings(models_cfg: dict, model: str, spec: ModelSpec) -> dict:
    """Ours' section, the topology parts' and the learned forcing's where the prior has them,
    and its own entry of the search over omega (another model's leaves it alone)."""
    out = {spec.family: models_cfg[spec.family]}
    if spec.parts == "topology":
        out["topology"] = models_cfg["topology"]
    if spec.forcing == "learned":
        out["blind"] = models_cfg["blind"]
    if searches_omega(models_cfg, model):
        out["omega_search"] = {**models_cfg["omega_search"], "models": [model]}
    return out


def _build_prior(b: Build) -> BaseModel:
    """An oscillator prior: K parts (the configuration's unless given), ours' oscillators, the
    parts its spec names (k-means or topology, chained or not), the measured wind or a learned
    forcing, and the search over omega where the model is listed for it.

    Raises:
        ValueError: a configuration ours does not have when K is not given, or a learned-forcing
            prior listed for the search over omega.
    """
    # here: torch (module docstring)
    from physgs.models.blind import BlindOscillatorPrior
    from physgs.models.ours import OscillatorPrior

    cfg, spec, K = b.cfg, b.spec, b.K
    if K is None:
        c = cfg.get("configs", {}).get(b.config)
        if c is None:
            raise ValueError(
                f"ours has no configuration {b.config!r} and no K was given; valid: "
                f"{sorted(cfg.get('configs', {}))}"
            )
        K = c["K"]
    o = cfg[spec.family]
    options = {}
    if searches_omega(cfg, b.name):
        options["search"] = OmegaSearch.from_config(cfg["omega_search"])
    if spec.parts == "topology":
        t = cfg["topology"]
        options.update(
            segmentation="topology",
            knn=int(t["knn"]),
            parent=b.parent,
            canonical_pose=canonical_pose_of(t),
        )
    cls = OscillatorPrior
    if spec.forcing == "learned":
        if options.get("search") is not None:
            raise ValueError(
                f"{b.name} has no search over omega: remove it from models/omega_search"
            )
        cls = BlindOscillatorPrior
        options["forcing_hz"] = float(cfg["blind"]["forcing_hz"])
    return cls(
        b.ctx,
        b.canonical,
        K=int(K),
        **{k: o[k] for k in OSCILLATOR_KEYS},
        kmeans_n_init=o["kmeans_n_init"],
        seed=b.seed,
        labels=b.labels,
        chain=spec.chain,
        **options,
    )


FAMILIES: dict[str, Family] = {
    "static": Family(_no_settings, _build_static),
    "mlp": Family(_field_settings, _build_field),
    "d3dgs": Family(_field_settings, _build_field),
    "ours": Family(_prior_settings, _build_prior),
    "truth_motion": Family(_no_settings, _build_true_motion),
}
"""``ModelSpec.family`` (its section under ``models:``) -> its family: what its models read and
how one is built; ``build_model`` and ``model_settings`` call it, never branch on it."""
