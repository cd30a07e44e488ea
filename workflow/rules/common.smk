# Paths, wildcard constraints, input functions and narrow params of every rule. The workflow
# owns the file layout; the library receives the files (and only the settings) a job reads.
import os
from types import SimpleNamespace

import physgs.config as _config
import physgs.experiments.fit_curve as _fit_curve
import physgs.experiments.kmatch as _kmatch
import physgs.experiments.kselect as _kselect
import physgs.experiments.sweep as _sweep
import physgs.models.registry as _models
import physgs.provenance as _provenance
import physgs.testbed.variant as _variant
import physgs.oma.settings as _oma
import physgs.tracks.settings as _tracks
from physgs.experiments.recipe import canonical as _canonical
from physgs.experiments.recipe import job_spec as _job_spec
from physgs.recovery.run import null_settings as _null_settings
from physgs.report import build as _build
from physgs.report import claim_cells as _claim_cells

# Torch's OpenMP threads spin-wait by default, which starves the other job on a 2-core machine
# (measured: 20x slower projection); jobs inherit this environment.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

TREES = list(CFG["trees"])
# the damping benchmark: each listed tree is also built as <tree>_damping (the damping variant)
DAMPING = CFG["damping_benchmark"]
DAMPING_TREES = [_variant.damping_id(t) for t in DAMPING["trees"]]
TESTBEDS = [*TREES, *DAMPING_TREES]  # every testbed id a rule may see as {tree}
SEEDS = [int(s) for s in CFG["seeds"]]  # training seeds; the testbed's is CFG["seed"]
STUDY_SEEDS = _config.study_seeds(CFG)  # the sweep's and the fit curve's seeds (a subset)
TESTBED_SEEDS = bool(CFG["testbed_seeds"])
CONFIGS = dict(CFG["models"]["configs"])  # name -> {conditions, K}
TRAIN_JOBS = _models.training_jobs(CONFIGS)
# the parts study (tab_parts, fig_parts): ours' variants with parts cut along the tree, on every
# tree and on the damping benchmark's testbeds of those trees
PARTS = CFG["parts_study"]
PARTS_MODELS = list(PARTS["models"])
PARTS_CONFIGS = {c: CONFIGS[c] for c in PARTS["configs"]} if PARTS_MODELS else {}
PRIORS = ["ours", *PARTS_MODELS]  # every oscillator prior the run trains
#: what this run builds, as the report outputs' needs read it (physgs.report.outputs.Plan)
REPORT_PLAN = _build.Plan.from_config(CFG)
STAMP = _provenance.stamp(CFG)  # not a rerun trigger (see physgs.provenance.Stamp)
# the 2D-track control (docs/tracks.md): ours' oscillators fitted to point tracks of the training
# video, in these of ours' configurations (each with its K: physgs.tracks.settings.parts)
TRACKS_CONFIGS = list(CFG["tracks"]["configs"])
# on a damping testbed, the control runs in the damping benchmark's configurations only
TRACKS_DAMPING_CONFIGS = [c for c in DAMPING["configs"] if c in TRACKS_CONFIGS]
# output-only modal analysis of the training video (docs/blind.md): the configurations it runs in
OMA_CONFIGS = list(CFG["oma"]["configs"])
# the priors besides ours whose K is chosen from the data (models/kselect/priors), each trained
# as <prior>_auto by the rules of ours' (kselect.smk)
KSELECT_PRIORS = list(_kselect.selected_models(CFG["models"]["kselect"])[1:])

# ---- file layout ------------------------------------------------------------------------------
# The testbed is one fixed instance per tree (testbed seed CFG["seed"]); every result of a
# training seed lives under seed{seed}/. With testbed_seeds, seed s also has its own instance.
OBSERVED = "results/testbed/{tree}/observed.npz"
TRUTH = "results/testbed/{tree}/truth.npz"
STATS = "results/testbed/{tree}/stats.json"
SEEDED_OBSERVED = "results/testbed/{tree}/seed{seed}/observed.npz"
SEEDED_TRUTH = "results/testbed/{tree}/seed{seed}/truth.npz"
SEEDED_STATS = "results/testbed/{tree}/seed{seed}/stats.json"
CKPT = "results/models/{tree}/seed{seed}/{model}_{config}.pt"
LOSS = "results/models/{tree}/seed{seed}/{model}_{config}.loss.csv"
EVAL = "results/eval/{tree}/seed{seed}/{model}_{config}.npz"
TRAJ = "results/eval/{tree}/seed{seed}/{model}_{config}.traj.npz"
PANELS = "results/eval/{tree}/seed{seed}/{model}_{config}.panels.npz"
# any recovery method's record (physgs.models.registry.RECOVERY_METHODS: the priors, the
# forcing-free priors, the 2D-track control, the output-only analysis), ours' format; the rule
# of each method's entry writes it (recovery_record)
RECOVERY = "results/recovery/{tree}/seed{seed}/{method}_{config}.json"
PARTS_RECORD = "results/parts/{tree}/seed{seed}.npz"  # the priors' segmentations and purity
KMATCH = "results/parts/{tree}/seed{seed}_chain_K{K}.json"  # the chained prior at a smaller K
NULL = "results/recovery/{tree}/seed{seed}/null_K{K}.json"
KSELECT = "results/kselect/{tree}/seed{seed}.json"
PRIOR_KSELECT = "results/kselect/{tree}/seed{seed}/{model}.json"  # a prior's besides ours'
SWEEP_POINT = "results/speed_accuracy/seed{seed}/{point}.json"
FIT_POINT = "results/fit_curve/{tree}/seed{seed}/{model}_it{iterations}.json"
# a field trained with the window-normalised time encoding (the fit curve's diagnostic series)
FIT_WINDOW_POINT = "results/fit_curve/{tree}/seed{seed}/{model}_it{iterations}_windowtime.json"
# the recipe search of one model on one tree (target search, outside all): its trials, every
# held-out score they reported, and the best recipe as a config block
SEARCH = "results/search/{tree}/{model}.{what}"
TABLE = "results/tables/{name}.{ext}"
FIGURE = "results/figures/{name}.{ext}"
# the tracks control: one condition's tracks (observed only; per instance like the testbed), the
# fit of one configuration, and its scores and recovery record (read the truth)
TRACKS = "results/tracks/{tree}/c{condition}.npz"
SEEDED_TRACKS = "results/tracks/{tree}/seed{seed}/c{condition}.npz"
TRACKS_FIT = "results/tracks/{tree}/seed{seed}/fit_{config}.npz"
TRACKS_EVAL = "results/tracks/{tree}/seed{seed}/eval_{config}.json"
TRACKS_FIELDS = "results/tracks/{tree}/seed{seed}/fields_{config}.json"  # the fields at the tracks
# output-only modal analysis: the modes of the training video (observed only; its recovery
# record: RECOVERY)
OMA_MODES = "results/oma/{tree}/seed{seed}/modes_{config}.npz"
#: need kind (physgs.report.build.needs) -> path template
NEED_PATHS = {
    "eval": EVAL,
    "traj": TRAJ,
    "panels": PANELS,
    "loss": LOSS,
    "recovery": RECOVERY,
    "parts": PARTS_RECORD,
    "kmatch": KMATCH,
    "null": NULL,
    "kselect": KSELECT,
    "prior_kselect": PRIOR_KSELECT,
    "stats": STATS,
    "instance_stats": SEEDED_STATS,
    "table": TABLE.replace("{ext}", "csv"),
    "tracks_eval": TRACKS_EVAL,
    "tracks_fields": TRACKS_FIELDS,
    "tracks_fit": TRACKS_FIT,
    # a figure reads the instance of its seed (the one instance without testbed_seeds)
    "tracks": SEEDED_TRACKS if TESTBED_SEEDS else TRACKS,
    "observed": SEEDED_OBSERVED if TESTBED_SEEDS else OBSERVED,
    "truth": SEEDED_TRUTH if TESTBED_SEEDS else TRUTH,
    "oma_modes": OMA_MODES,
}
SA_TREE = CFG["speed_accuracy"]["tree"]
SWEEP_POINTS = _sweep.sweep_points(CFG)
FC = CFG["speed_accuracy"]["fit_curve"]
#: the fit curve's profile-budget point is the pipeline's own job: these models' evaluations
FC_PROFILE_MODELS = ["static", *FC["models"], *_models.REFERENCE_NAMES]


wildcard_constraints:
    tree="|".join(TESTBEDS),
    model="|".join([*_models.MODEL_NAMES, *_models.PRIOR_VARIANT_NAMES, *_models.REFERENCE_NAMES]),
    # a recovery method's id (registry.RECOVERY_METHODS) or a parts-study variant's (tab_parts)
    method="|".join(dict.fromkeys([*_models.RECOVERY_METHOD_NAMES, *_models.PRIOR_VARIANT_NAMES])),
    config="|".join([*CONFIGS, _models.AUTO_CONFIG]),
    K=r"\d+",
    point="|".join(SWEEP_POINTS),
    iterations=r"\d+",
    seed=r"\d+",
    condition=r"\d+",
    name="|".join([*_build.TABLES, *_build.FIGURES]),


# ---- input functions ----------------------------------------------------------------------
def recovery_record(method):
    """The record template of one recovery method ({tree}, {seed}, {config} left to the job),
    checked against the rule its entry names (physgs.models.registry.RECOVERY_METHODS)."""
    return RECOVERY.replace("{method}", method)


def recovery_ckpt(wildcards):
    """The checkpoint whose recovery rule ``recovery`` scores (a trained prior)."""
    return CKPT.format(
        tree=wildcards.tree, seed=wildcards.seed, model=wildcards.method, config=wildcards.config
    )


def testbed_files(tree, seed):
    """{observed, truth, stats} paths of the instance training seed ``seed`` reads: the tree's
    one instance, or with testbed_seeds the instance built with testbed seed ``seed``."""
    if TESTBED_SEEDS:
        return {
            "observed": SEEDED_OBSERVED.format(tree=tree, seed=seed),
            "truth": SEEDED_TRUTH.format(tree=tree, seed=seed),
            "stats": SEEDED_STATS.format(tree=tree, seed=seed),
        }
    return {
        "observed": OBSERVED.format(tree=tree),
        "truth": TRUTH.format(tree=tree),
        "stats": STATS.format(tree=tree),
    }


def observed_input(wildcards):
    return testbed_files(wildcards.tree, wildcards.seed)["observed"]


def truth_input(wildcards):
    return testbed_files(wildcards.tree, wildcards.seed)["truth"]


def stats_input(wildcards):
    return testbed_files(wildcards.tree, wildcards.seed)["stats"]


def train_input(wildcards):
    """The observed dataset of the tree; refuses (model, config) pairs that are never trained."""
    if wildcards.config not in _models.configs_for(wildcards.model, CONFIGS):
        raise ValueError(
            f"model '{wildcards.model}' is not trained in configuration '{wildcards.config}'; "
            f"valid: {_models.configs_for(wildcards.model, CONFIGS)} (joint configurations "
            "are ours only)"
        )
    return observed_input(wildcards)


def need_paths(needs):
    """need key -> path for need tuples of physgs.report.build."""
    out = {}
    for need in needs:
        fields = dict(zip(_build.NEED_FIELDS[need[0]], need[1:]))
        out[_build.key(need)] = NEED_PATHS[need[0]].format(**fields)
    return out


def report_inputs(wildcards):
    """need key -> path of every file table or figure ``name`` reads."""
    return need_paths(_build.needs(wildcards.name, REPORT_PLAN))


# ---- narrow params: each job sees only the settings it reads -------------------------------
def train_params(wildcards):
    """The job's narrow settings, its tree's recipe (``recipes``) merged in."""
    return _job_spec(
        CFG, wildcards.model, wildcards.config, seed=int(wildcards.seed), tree=wildcards.tree
    )


def train_runtime(wildcards):
    """Minutes: generous (about 1 s per iteration of the job's own budget) so a cluster never
    kills a default job."""
    return 10 + train_params(wildcards)["train"]["iterations"] // 60


def search_job(wildcards):
    """The searched model's single job on the tree (its recipe the base; the paper's instance,
    the config's seed): every trial of the search is this job with the trial's recipe over it."""
    return _job_spec(
        CFG, wildcards.model, _models.BASE_CONFIG, seed=CFG["seed"], tree=wildcards.tree
    )


def kselect_params(wildcards):
    """The prior's base training job and its K-selection settings (ours' without {model})."""
    model = getattr(wildcards, "model", _kselect.BASE_MODEL)
    return _canonical(
        {
            "job": _job_spec(
                CFG, model, _models.BASE_CONFIG, seed=int(wildcards.seed), tree=wildcards.tree
            ),
            "kselect": _kselect.settings_for(CFG["models"]["kselect"], model),
        }
    )


def kselect_runtime(model):
    """Minutes of one K selection: about 1 s per iteration per candidate, generous for a cluster."""
    ks = _kselect.settings_for(CFG["models"]["kselect"], model)
    return 10 + len(ks["candidates"]) * ks["iterations"] // 60


def null_params(wildcards):
    return _null_settings(CFG, int(wildcards.K), seed=int(wildcards.seed))


def report_params(wildcards):
    return _canonical(_build.settings_for(wildcards.name, CFG))


def sweep_params(wildcards):
    return _sweep.point_settings(
        CFG, wildcards.point, seed=int(wildcards.seed), testbed_seeds=TESTBED_SEEDS
    )


def sweep_inputs(wildcards):
    """The sweep tree's dataset for this seed's points."""
    f = testbed_files(SA_TREE, wildcards.seed)
    return {"observed": f["observed"], "truth": f["truth"]}


def fit_point_params(wildcards):
    return _fit_curve.point_job(
        CFG,
        wildcards.model,
        int(wildcards.iterations),
        seed=int(wildcards.seed),
        tree=wildcards.tree,
    )


def fit_window_params(wildcards):
    return _fit_curve.point_job(
        CFG,
        wildcards.model,
        int(wildcards.iterations),
        seed=int(wildcards.seed),
        window_time=True,
        tree=wildcards.tree,
    )


def fit_curve_inputs(wildcards):
    """Per tree of the fit curve, the extra-budget points of every seed (key points_{tree}) and the
    pipeline's own evaluation and loss log of each model and seed at the profile's budget (keys
    eval_{tree}_{model}_{seed}, loss_{tree}_{model}_{seed})."""
    cfg = _models.BASE_CONFIG
    out = {}
    for tree in _fit_curve.trees_of(CFG):
        out[f"points_{tree}"] = [
            FIT_POINT.format(tree=tree, seed=s, model=m, iterations=b)
            for m in FC["models"]
            for b in _fit_curve.extra_budgets(CFG, tree, m)
            for s in STUDY_SEEDS
        ] + [
            # the window-time series at the field's own budget
            FIT_WINDOW_POINT.format(
                tree=tree, seed=s, model=m, iterations=_fit_curve.own_budget(CFG, tree, m)
            )
            for m in _fit_curve.window_models(CFG)
            for s in STUDY_SEEDS
        ]
        for s in STUDY_SEEDS:
            for m in FC_PROFILE_MODELS:
                out[f"eval_{tree}_{m}_{s}"] = EVAL.format(tree=tree, seed=s, model=m, config=cfg)
                out[f"loss_{tree}_{m}_{s}"] = LOSS.format(tree=tree, seed=s, model=m, config=cfg)
    return out


def testbed_params(wildcards):
    """The settings testbed {tree} is built from: <tree>_damping is <tree> with the damping
    variant; the faithful variant's params omit the damping block (it changes nothing there)."""
    t, variant = _variant.parse_id(wildcards.tree)
    # only this tree's vertex count: another tree's edit leaves it alone
    tb = {**CFG["testbed"], "vertices": {t: CFG["testbed"]["vertices"][t]}}
    if variant == _variant.DAMPING:
        tb["variant"] = _variant.DAMPING
    seed = int(getattr(wildcards, "seed", CFG["seed"]))  # a seeded instance (testbed_seeds)
    return _canonical(
        {
            "testbed": _variant.effective_settings(tb),
            # its role picks claims, not geometry: editing it reruns the ledger, not the testbed
            "preset": {k: v for k, v in CFG["presets"][t].items() if k != "role"},
            "seed": seed,
            "tree": t,
        }
    )


def parts_inputs(wildcards):
    """The truth and each prior's checkpoint in the base configuration (keys: the model ids)."""
    out = {"truth": truth_input(wildcards)}
    for m in PRIORS:
        out[m] = CKPT.format(
            tree=wildcards.tree, seed=wildcards.seed, model=m, config=_models.BASE_CONFIG
        )
    return out


def parts_jobs():
    """Checkpoints of the parts study's variants: every tree and damping testbed, seed and
    configuration of the study (what `all` trains beyond the methods)."""
    trees = [*TREES, *[_variant.damping_id(t) for t in DAMPING["trees"] if t in TREES]]
    return [
        CKPT.format(tree=t, seed=s, model=m, config=c)
        for t in trees
        for s in SEEDS
        for m in PARTS_MODELS
        for c in PARTS_CONFIGS
    ]


def kmatch_params(wildcards):
    job = _job_spec(
        CFG, "ours_chain", _models.BASE_CONFIG, seed=int(wildcards.seed), tree=wildcards.tree
    )
    return _kmatch.point_job(job, int(wildcards.K))


def recovery_damping_params(wildcards):
    """Per-part damping scores and their null for the damping benchmark's testbeds (both
    variants); None elsewhere."""
    t, _ = _variant.parse_id(wildcards.tree)
    if t not in DAMPING["trees"] or wildcards.config not in DAMPING["configs"]:
        return None
    return {
        "zeta_range": [float(z) for z in CFG["testbed"]["damping"]["zeta_range"]],
        "seed": int(wildcards.seed),
    }


# ---- the 2D-track control (tracks.smk) ---------------------------------------------------------
def tracks_file(tree, seed, condition):
    """The tracks of ``condition``'s video of the instance training seed ``seed`` reads."""
    return (SEEDED_TRACKS if TESTBED_SEEDS else TRACKS).format(
        tree=tree, seed=seed, condition=condition
    )


def tracks_configs(tree):
    """The configurations the tracks control fits and scores on testbed ``tree``, in the order
    of the batched rules' outputs: tracks/configs on a faithful tree, the damping benchmark's
    among them on a damping testbed."""
    return TRACKS_DAMPING_CONFIGS if tree in DAMPING_TREES else TRACKS_CONFIGS


def tracks_outputs(pattern, configs):
    """``pattern`` for each configuration ({tree} and {seed} left to the job): the batched
    rules' outputs. With none, the pattern itself, which their config constraint never
    matches (the rule then makes nothing)."""
    return expand(pattern, config=configs, allow_missing=True) if configs else [pattern]


def fit_tracks_params(wildcards):
    """The fits' narrow settings, one per configuration of the tree in output order
    (physgs.tracks.settings.fit_job): K and its key, the conditions, the fit's settings and
    ours' oscillator settings."""
    seed = int(wildcards.seed)
    return [_tracks.fit_job(CFG, c, seed) for c in tracks_configs(wildcards.tree)]


def fit_tracks_inputs(wildcards):
    """The observed dataset (wind, frame rate, lead-in) and the tracks of every condition a
    configuration of the tree fits (keys c<condition>); never the truth."""
    out = {"observed": observed_input(wildcards)}
    for j in fit_tracks_params(wildcards):
        for c in j["conditions"]:
            out[f"c{c}"] = tracks_file(wildcards.tree, wildcards.seed, c)
    return out


def tracks_evaluate_inputs(wildcards):
    """Per configuration of the tree its fit and ours' checkpoint in it (scored at the same
    tracked points; keys fit_<config>, ours_<config>), the training video's tracks, the dataset,
    the truth and its statistics."""
    t, s = wildcards.tree, wildcards.seed
    out = {"tracks": tracks_file(t, s, 0), **testbed_files(t, s)}
    for c in tracks_configs(t):
        out[f"fit_{c}"] = TRACKS_FIT.format(tree=t, seed=s, config=c)
        out[f"ours_{c}"] = CKPT.format(tree=t, seed=s, model="ours", config=c)
    return out


def tracks_evaluate_params(wildcards):
    """recovery_damping_params of each configuration of the tree, in output order."""
    return [
        recovery_damping_params(SimpleNamespace(tree=wildcards.tree, seed=wildcards.seed, config=c))
        for c in tracks_configs(wildcards.tree)
    ]


def tracks_fields_inputs(wildcards):
    """The fit, the training video's tracks, the dataset and the truth, and the checkpoints of
    the learned fields of tracks/fields the pipeline trains there (single, faithful testbeds)."""
    t, s, c = wildcards.tree, wildcards.seed, wildcards.config
    fields = _tracks.fields_scored(CFG, c, t)
    if not fields:
        raise ValueError(f"no learned field of tracks/fields is trained in {c} on {t}")
    tb = testbed_files(t, s)  # the bones' visibility (stats) is not read here
    return {
        "fit": TRACKS_FIT.format(tree=t, seed=s, config=c),
        "tracks": tracks_file(t, s, 0),
        "observed": tb["observed"],
        "truth": tb["truth"],
        **{f"field_{m}": CKPT.format(tree=t, seed=s, model=m, config=c) for m in fields},
    }


# ---- output-only modal analysis (oma.smk) -------------------------------------------------------
def oma_identify_params(wildcards):
    """The configuration's conditions and the analysis' settings (physgs.oma.settings)."""
    return _oma.identify_params(CFG, wildcards.config)


def oma_recovery_params(wildcards):
    """K, seed, k-means restarts and ours' solver settings (physgs.oma.settings)."""
    return _oma.recovery_params(CFG, wildcards.config, int(wildcards.seed))


def oma_recovery_inputs(wildcards):
    """The modes, the dataset (wind for the matcher's simulation), the truth and its statistics."""
    t, s, c = wildcards.tree, wildcards.seed, wildcards.config
    return {"modes": OMA_MODES.format(tree=t, seed=s, config=c), **testbed_files(t, s)}
